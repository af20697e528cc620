// plant view's HTTP server: a fixed route table on 127.0.0.1, answered through the HTTP server
// module (view_http.hpp; cpp-httplib lives there, loaded only by `plant view`). No part of a
// request names a file: the page's files are built into the program and the model is made in
// memory. Requests whose Host or Origin is not this loopback address and port are refused (a web
// page elsewhere could otherwise reach the server through DNS rebinding); the page can change
// params and the seed, which derives again, and nothing else.
#include "cmd_view.hpp"

#include <nlohmann/json.hpp>

#include <charconv>
#include <cmath>
#include <cstring>
#include <type_traits>

namespace plant::cli {

namespace {

bool allowed_host(const std::string& host, int port) {
    return host == "127.0.0.1:" + std::to_string(port) || host == "localhost:" + std::to_string(port);
}

bool allowed_origin(const view_http::Request& req, int port) {
    if (!req.has_header("Origin")) return true; // same-origin GETs and tools send none
    const std::string origin = req.header("Origin");
    return origin.rfind("http://", 0) == 0 && allowed_host(origin.substr(7), port);
}

void refuse(view_http::Response& res, int status, const std::string& why) {
    res.status = status;
    res.set_content(why + "\n", "text/plain; charset=utf-8");
}

// The checks every request passes before any route sees it: true when it is refused (answered).
bool screen(const view_http::Request& req, view_http::Response& res, int port) {
    res.set_header("X-Content-Type-Options", "nosniff");
    res.set_header("Cache-Control", "no-store");
    if (!allowed_host(req.header("Host"), port) || !allowed_origin(req, port)) {
        refuse(res, 403, "plant view answers only requests for 127.0.0.1:" + std::to_string(port));
        return true;
    }
    if (req.path.empty() || req.path[0] != '/' || req.path.find("..") != std::string::npos ||
        req.target.find("..") != std::string::npos || req.path.find('\\') != std::string::npos ||
        req.path.find("//") != std::string::npos) {
        refuse(res, 400, "plant view serves only its own routes");
        return true;
    }
    return false;
}

void serve_asset(const view_http::Request& req, view_http::Response& res) {
    for (const ViewAsset* a = kViewAssets; a->route; ++a) {
        if (req.path != a->route) continue;
        res.set_content(std::string(a->begin, a->end), a->mime);
        res.set_header("Content-Security-Policy",
                       "default-src 'self'; img-src 'self' blob: data:; connect-src 'self' blob: data:; "
                       "style-src 'self' 'unsafe-inline'");
        return;
    }
    refuse(res, 404, "no such page");
}

// Query parameter `name` read whole as a number of type T (an int, or a finite double); false
// when it is missing or not that.
template <typename T> bool query_number(const view_http::Request& req, const char* name, T& out) {
    if (!req.has_param(name)) return false;
    const std::string s = req.param(name);
    auto r = std::from_chars(s.data(), s.data() + s.size(), out);
    if (r.ec != std::errc() || r.ptr != s.data() + s.size()) return false;
    if constexpr (std::is_floating_point_v<T>) return std::isfinite(out);
    return true;
}

// Sends what `make` returns for a kept step (404 without a plant or step; 500 on an error making it).
template <typename Make> void answer(view_http::Response& res, const char* mime, Make make) {
    try {
        auto body = make();
        if (!body) return refuse(res, 404, "no plant (the grammar has an error) or that step was not kept");
        res.set_content(std::move(*body), mime);
    } catch (const RuntimeError& e) {
        refuse(res, 500, e.message);
    } catch (const std::exception& e) {
        refuse(res, 500, e.what());
    }
}

void serve_model(ViewModel& model, const view_http::Request& req, view_http::Response& res) {
    int step = -1;
    if (req.has_param("step") && !query_number(req, "step", step))
        return refuse(res, 400, "step: a whole number");
    answer(res, "model/gltf-binary", [&] { return model.glb(step); });
}

// GET /api/pick?step=K&kind=tube|organ&x=&y=&z=[&ox=&oy=&oz=]: what the click hit (docs/view.md).
void serve_pick(ViewModel& model, const view_http::Request& req, view_http::Response& res) {
    auto number = [&](const char* name, double& out) { return query_number(req, name, out); };
    ViewPick q;
    const std::string kind = req.has_param("kind") ? req.param("kind") : "tube";
    if (kind != "tube" && kind != "organ") return refuse(res, 400, "kind: tube or organ");
    q.kind = kind == "tube" ? ViewPick::Tube : ViewPick::Organ;
    int step = -1;
    if (req.has_param("step") && !query_number(req, "step", step))
        return refuse(res, 400, "step: a whole number");
    if (!number("x", q.point.x) || !number("y", q.point.y) || !number("z", q.point.z))
        return refuse(res, 400, "x, y and z: the point hit, three finite numbers");
    q.origin = q.point;
    if (q.kind == ViewPick::Organ &&
        (!number("ox", q.origin.x) || !number("oy", q.origin.y) || !number("oz", q.origin.z)))
        return refuse(res, 400, "ox, oy and oz: where the organ hit is placed, three finite numbers");
    answer(res, "application/json", [&] { return model.pick(step, q); });
}

// POST /api/controls {"params": {"name": number}, "seed": "digits" or null}
void set_controls(ViewModel& model, ViewEvents& events, const view_http::Request& req,
                  view_http::Response& res) {
    ViewControls c;
    try {
        const auto j = nlohmann::json::parse(req.body);
        if (j.contains("params"))
            for (const auto& [name, value] : j.at("params").items()) c.params[name] = value.get<double>();
        if (j.contains("seed") && !j.at("seed").is_null()) {
            const std::string s = j.at("seed").get<std::string>();
            std::uint64_t v = 0;
            auto r = std::from_chars(s.data(), s.data() + s.size(), v);
            if (s.empty() || r.ec != std::errc() || r.ptr != s.data() + s.size())
                return refuse(res, 400, "the seed is a whole number from 0 to 2^64 - 1");
            c.seed = v;
        }
    } catch (const std::exception&) {
        return refuse(res, 400, "expected {\"params\": {\"name\": number}, \"seed\": \"digits\"}");
    }
    if (std::string why = model.set_controls(c); !why.empty()) return refuse(res, 400, why);
    events.publish(model.version());
    res.set_content(model.state_json(), "application/json");
}

// POST /api/edit {"step": k, "env": "ivy", "method": "cut", "args": [14, [0, 1, 0]]} or
// {"undo": true}: one edit method call before step k + 1 (docs/view.md, editing climbers).
void edit(ViewModel& model, ViewEvents& events, const view_http::Request& req, view_http::Response& res) {
    ViewEdit e;
    bool undo = false;
    try {
        const auto j = nlohmann::json::parse(req.body);
        undo = j.value("undo", false);
        if (!undo) {
            const auto& step = j.at("step");
            if (!step.is_number_integer() || step.get<std::int64_t>() < 0 ||
                step.get<std::int64_t>() > 1'000'000'000)
                return refuse(res, 400, "step: the whole number of the step shown");
            e.step = static_cast<int>(step.get<std::int64_t>());
            e.env = j.at("env").get<std::string>();
            e.method = j.at("method").get<std::string>();
            if (!j.at("args").is_array()) throw std::invalid_argument("args");
            for (const auto& a : j.at("args")) {
                std::vector<double> v;
                if (a.is_array())
                    for (const auto& x : a) v.push_back(x.get<double>());
                else
                    v.push_back(a.get<double>());
                e.args.push_back(std::move(v));
            }
        }
    } catch (const std::exception&) {
        return refuse(
            res, 400,
            "expected {\"step\": k, \"env\": name, \"method\": name, \"args\": [number or [x, y, z]]} "
            "or {\"undo\": true}");
    }
    if (undo) {
        if (!model.undo_edit()) return refuse(res, 400, "there is no edit to undo");
    } else if (std::string why = model.add_edit(e); !why.empty()) {
        return refuse(res, 400, why);
    }
    events.publish(model.version());
    res.set_content(model.state_json(), "application/json");
}

// GET /api/events: Server-Sent Events, one `model` event (the state) per new version.
void stream_events(ViewModel& model, ViewEvents& events, view_http::Response& res) {
    auto seen = std::make_shared<std::uint64_t>(0);
    res.stream_type = "text/event-stream";
    res.stream = [&model, &events, seen](const view_http::Response::Writer& write) {
        if (events.stopped()) return false;
        const std::uint64_t now = *seen == 0 ? model.version() : events.wait(*seen, 1000);
        if (events.stopped()) return false;
        std::string message = ": waiting\n\n"; // also finds out when the page has gone
        if (now != *seen) {
            *seen = now;
            message = "event: model\ndata: " + model.state_json() + "\n\n";
        }
        return write(message.data(), message.size());
    };
}

} // namespace

int serve_view(view_http::ServeFunction serve, ViewModel& model, ViewEvents& events,
               const ViewServerOptions& options, std::function<void(std::function<void()>)> set_stopper) {
    using view_http::Request, view_http::Response;
    view_http::ServeOptions o;
    o.host = "127.0.0.1";
    o.port = options.port;
    o.max_payload = 64 * 1024; // the controls' JSON is far smaller
    // the port actually bound, for the screen: known once listening (before any request)
    auto port = std::make_shared<std::atomic<int>>(options.port);
    o.screen = [port](const Request& req, Response& res) { return screen(req, res, *port); };
    auto route = [&o](const char* method, const char* pattern, view_http::Handler h) {
        o.routes.push_back({method, pattern, std::move(h)});
    };
    route("GET", "/api/state",
          [&](const Request&, Response& res) { res.set_content(model.state_json(), "application/json"); });
    route("GET", "/api/model.glb", [&](const Request& req, Response& res) { serve_model(model, req, res); });
    route("GET", "/api/pick", [&](const Request& req, Response& res) { serve_pick(model, req, res); });
    route("GET", "/api/events", [&](const Request&, Response& res) { stream_events(model, events, res); });
    route("POST", "/api/controls",
          [&](const Request& req, Response& res) { set_controls(model, events, req, res); });
    route("POST", "/api/edit", [&](const Request& req, Response& res) { edit(model, events, req, res); });
    route("GET", ".*", [](const Request& req, Response& res) { serve_asset(req, res); });
    o.set_stopper = std::move(set_stopper);
    o.on_listening = [&options, port](int bound) {
        *port = bound;
        if (options.on_listening) options.on_listening(bound);
    };
    return serve(o);
}

} // namespace plant::cli
