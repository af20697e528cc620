// plant-view-server.so: plant view's HTTP server on cpp-httplib, behind the plain interface of
// view_http.hpp. Only this file includes httplib.h; only `plant view` loads the module (dlopen),
// so no other plant process loads cpp-httplib or the TLS and compression libraries Debian's
// build of it needs. It knows nothing of plant: the routes and the screen come from the program.
#include "view_http.hpp"

#include <httplib.h>

#include <sys/socket.h>

namespace {

using plant::view_http::Request;
using plant::view_http::Response;

Request to_request(const httplib::Request& req) {
    Request r;
    r.method = req.method;
    r.path = req.path;
    r.target = req.target;
    r.body = req.body;
    r.headers.assign(req.headers.begin(), req.headers.end());
    r.params.assign(req.params.begin(), req.params.end());
    return r;
}

// Moves what a handler answered into httplib's response (as httplib's own set_content would:
// one Content-Type).
void apply(Response& from, httplib::Response& res) {
    if (from.status != -1) res.status = from.status;
    for (auto& [name, value] : from.headers) res.set_header(name, value);
    if (from.has_content) {
        res.body = std::move(from.body);
        res.headers.erase("Content-Type");
        res.set_header("Content-Type", from.content_type);
    }
    if (from.stream) {
        auto stream = std::move(from.stream);
        res.set_chunked_content_provider(from.stream_type, [stream](std::size_t, httplib::DataSink& sink) {
            return stream([&sink](const char* data, std::size_t size) { return sink.write(data, size); });
        });
    }
}

} // namespace

extern "C" __attribute__((visibility("default"))) int
plant_view_http_serve_v1(const plant::view_http::ServeOptions& options) {
    httplib::Server server;
    // SO_REUSEADDR only: httplib's default adds SO_REUSEPORT, which would let a second server
    // (another `plant view`, or any program of the same user) share the port and half the requests
    server.set_socket_options([](int sock) {
        int yes = 1;
        setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    });
    int port = options.port;
    if (port == 0) {
        port = server.bind_to_any_port(options.host);
        if (port < 0) return -1;
    } else if (!server.bind_to_port(options.host, port)) {
        return -1;
    }
    server.set_payload_max_length(options.max_payload);
    if (options.screen)
        server.set_pre_routing_handler([&options](const httplib::Request& req, httplib::Response& res) {
            Response r;
            const bool answered = options.screen(to_request(req), r);
            apply(r, res);
            return answered ? httplib::Server::HandlerResponse::Handled
                            : httplib::Server::HandlerResponse::Unhandled;
        });
    for (const auto& route : options.routes) {
        auto handler = [&route](const httplib::Request& req, httplib::Response& res) {
            Response r;
            route.handler(to_request(req), r);
            apply(r, res);
        };
        if (route.method == "POST")
            server.Post(route.pattern, handler);
        else
            server.Get(route.pattern, handler);
    }
    if (options.set_stopper) options.set_stopper([&server] { server.stop(); });
    if (options.on_listening) options.on_listening(port);
    server.listen_after_bind();
    if (options.set_stopper) options.set_stopper(nullptr);
    return port;
}
