// The interface between `plant view` and its HTTP server, a module of its own
// (plant-view-server.so, view_http_module.cpp) that only `plant view` loads, with dlopen: the
// HTTP library and the TLS and compression libraries it is built with stay out of every other
// plant process (docs/view.md, docs/architecture.md). Plain C++ types only, so that the program
// never sees the library's classes. The module is built with the program and from the same
// sources; when any type here changes, change the number in kViewServeSymbol too, so that a
// module of an older build is refused instead of misread.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace plant::view_http {

using Pairs = std::vector<std::pair<std::string, std::string>>;

// HTTP header names compare without regard to case.
inline bool same_name(std::string_view a, std::string_view b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i) {
        auto lower = [](char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; };
        if (lower(a[i]) != lower(b[i])) return false;
    }
    return true;
}

struct Request {
    std::string method;
    std::string path;   // decoded, without the query
    std::string target; // as sent, query included
    std::string body;
    Pairs headers; // in the order sent
    Pairs params;  // the query's, in the order sent

    bool has_header(std::string_view name) const { return find(headers, name, true) != nullptr; }
    // The first value of header `name`; empty when there is none.
    std::string header(std::string_view name) const {
        const std::string* v = find(headers, name, true);
        return v ? *v : std::string();
    }
    bool has_param(std::string_view name) const { return find(params, name, false) != nullptr; }
    std::string param(std::string_view name) const {
        const std::string* v = find(params, name, false);
        return v ? *v : std::string();
    }

  private:
    static const std::string* find(const Pairs& pairs, std::string_view name, bool any_case) {
        for (const auto& [k, v] : pairs)
            if (any_case ? same_name(k, name) : k == name) return &v;
        return nullptr;
    }
};

struct Response {
    int status = -1; // -1: unchanged (200 once a route has answered)
    Pairs headers;   // added to the response in this order
    // The body and its Content-Type (set_content); has_content false: none set.
    bool has_content = false;
    std::string body, content_type;
    void set_content(std::string b, std::string type) {
        body = std::move(b);
        content_type = std::move(type);
        has_content = true;
    }
    void set_header(std::string name, std::string value) {
        headers.emplace_back(std::move(name), std::move(value));
    }
    // A body sent in chunks instead (Server-Sent Events): `stream` is called again and again, each
    // time with a writer for the next chunk, until it returns false (or a write fails: the
    // writer returns false when the client has gone).
    using Writer = std::function<bool(const char* data, std::size_t size)>;
    std::function<bool(const Writer&)> stream;
    std::string stream_type;
};

using Handler = std::function<void(const Request&, Response&)>;

struct Route {
    std::string method;  // "GET" (which answers HEAD too) or "POST"
    std::string pattern; // a regular expression the whole path matches
    Handler handler;
};

struct ServeOptions {
    std::string host; // the address to listen on
    int port = 0;     // 0: any free port
    std::size_t max_payload = 64 * 1024;
    // Sees every request before the routes: returns true when it has answered it (the routes
    // are skipped), false to pass it on, with whatever headers it added kept.
    std::function<bool(const Request&, Response&)> screen;
    std::vector<Route> routes;                  // the first that matches answers; none: 404
    std::function<void(int port)> on_listening; // called with the bound port before serving
    // Called with a function that stops the server (from any thread) once it is listening, and
    // with an empty function once it has stopped.
    std::function<void(std::function<void()>)> set_stopper;
};

// The module's one entry point, found by name: serves until stopped and returns the port it
// served on, or -1 when it could not bind.
using ServeFunction = int (*)(const ServeOptions&);
inline constexpr const char* kViewServeSymbol = "plant_view_http_serve_v1";
inline constexpr const char* kViewServerModule = "plant-view-server.so";

// Finds and loads the module (view_http_load.cpp): PREFIX/lib/plant/ for an installed PREFIX/bin/plant,
// then the program's own folder (the build tree). Returns null and sets `error` (a whole
// message) when it is missing or unusable; `missing` tells which.
ServeFunction load_view_server(std::string& error, bool& missing);

} // namespace plant::view_http
