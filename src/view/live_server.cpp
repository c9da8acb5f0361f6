#include "swirl/view/live_server.hpp"

#include <chrono>
#include <deque>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <variant>
#include <utility>  // before Boost 1.74's asio, which uses std::exchange without it
#include <vector>

#include <boost/asio.hpp>
#include <boost/beast.hpp>
#include <boost/beast/websocket.hpp>
#include <fmt/format.h>

#include "web_assets.hpp"

namespace swirl::view {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;

namespace {

// The path and the token of a request target "/path?token=abc".
struct Target {
  std::string path, token;
};
Target split_target(std::string_view target) {
  Target t;
  const std::size_t q = target.find('?');
  t.path = std::string(target.substr(0, q));
  if (q == std::string_view::npos) return t;
  std::string_view query = target.substr(q + 1);
  while (!query.empty()) {
    const std::size_t amp = query.find('&');
    const std::string_view pair = query.substr(0, amp);
    if (pair.substr(0, 6) == "token=") t.token = std::string(pair.substr(6));
    if (amp == std::string_view::npos) break;
    query.remove_prefix(amp + 1);
  }
  return t;
}

}  // namespace

struct LiveServer::Impl {
  ServerOptions options;
  std::function<void(const Control&)> on_control;
  std::function<std::string()> hello;
  std::function<void(const std::string&)> log;
  net::io_context ioc{1};
  tcp::acceptor acceptor{ioc};
  std::thread thread;
  std::uint16_t bound_port = 0;

  std::mutex mutex;  // latest, latest_seq, mesh, mesh_seq
  std::shared_ptr<const std::string> latest;
  std::uint64_t latest_seq = 0;
  std::shared_ptr<const std::string> mesh;  // the newest surface mesh; null while nobody wants one
  std::uint64_t mesh_seq = 0;
  std::atomic<std::size_t> surface_viewers{0};  // changed on the I/O thread only

  class WsSession;
  std::vector<std::weak_ptr<WsSession>> sessions;  // the I/O thread's only

  std::atomic<std::uint64_t> frames_sent{0}, bytes_sent{0}, controls{0}, dropped{0}, session_count{0};
  std::atomic<std::uint64_t> meshes_sent{0}, mesh_bytes_sent{0};

  // A viewer's surface turned on or off (on the I/O thread).
  void count_surface(bool on) {
    if (on) {
      ++surface_viewers;
    } else if (--surface_viewers == 0) {
      std::lock_guard lock(mutex);
      mesh.reset();
    }
  }

  void say(const std::string& line) {
    if (log) log(line);
  }
  // The 1st, 10th, 100th, ... dropped message is logged: a hostile page cannot flood the terminal.
  void drop(const std::string& why) {
    const std::uint64_t k = ++dropped;
    std::uint64_t p = 1;
    while (p < k) p *= 10;
    if (p == k) say(fmt::format("swirl view: dropped a message from a viewer ({}; {} so far)", why, k));
  }

  void accept();
  void pump_all() {
    std::erase_if(sessions, [](const std::weak_ptr<WsSession>& s) { return s.expired(); });
    for (auto& w : sessions)
      if (auto s = w.lock()) s->pump();
  }

  class WsSession : public std::enable_shared_from_this<WsSession> {
   public:
    WsSession(Impl& server, tcp::socket socket) : server_(server), ws_(std::move(socket)) {}

    void start(http::request<http::string_body> request) {
      ws_.read_message_max(server_.options.max_message);
      ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
      auto self = shared_from_this();
      ws_.async_accept(request, [self](beast::error_code ec) {
        if (ec) return;
        ++self->server_.session_count;
        self->server_.sessions.push_back(self);
        self->set_surface(self->server_.options.surface_on_connect);
        self->texts_.push_back(self->server_.hello ? self->server_.hello() : std::string("{}"));
        self->pump();
        self->read();
      });
    }

    void send_text(std::string text) {
      texts_.push_back(std::move(text));
      pump();
    }

    // This viewer's surface on or off (counted by the server while the session lives).
    void set_surface(bool on) {
      if (on == surface_) return;
      surface_ = on;
      server_.count_surface(on);
    }

    // Writes the next text, else the newest frame or mesh not yet sent (the
    // one not sent last when both are new), unless a write is in flight.
    void pump() {
      if (writing_ || closed_) return;
      auto self = shared_from_this();
      if (!texts_.empty()) {
        text_ = std::move(texts_.front());
        texts_.pop_front();
        writing_ = true;
        ws_.text(true);
        ws_.async_write(net::buffer(text_), [self](beast::error_code ec, std::size_t) { self->written(ec, 0, false); });
        return;
      }
      bool mesh = false;
      {
        std::lock_guard lock(server_.mutex);
        const bool new_frame = server_.latest && server_.latest_seq != sent_seq_;
        const bool new_mesh = surface_ && server_.mesh && server_.mesh_seq != sent_mesh_seq_;
        if (!new_frame && !new_mesh) return;
        mesh = new_mesh && (!new_frame || last_was_frame_);
        if (mesh) {
          binary_ = server_.mesh;
          sent_mesh_seq_ = server_.mesh_seq;
        } else {
          binary_ = server_.latest;
          sent_seq_ = server_.latest_seq;
        }
      }
      last_was_frame_ = !mesh;
      writing_ = true;
      ws_.binary(true);
      ws_.async_write(net::buffer(*binary_),
                      [self, mesh](beast::error_code ec, std::size_t n) { self->written(ec, n, mesh); });
    }

   private:
    void written(beast::error_code ec, std::size_t binary_bytes, bool mesh) {
      writing_ = false;
      if (ec) {
        mark_closed();
        return;
      }
      if (binary_bytes > 0) {
        if (mesh) {
          ++server_.meshes_sent;
          server_.mesh_bytes_sent += binary_bytes;
        } else {
          ++server_.frames_sent;
          server_.bytes_sent += binary_bytes;
        }
        binary_.reset();
      }
      pump();
    }

    // The session is over: it no longer wants meshes. (Here, on a failed read
    // or write, which every closed connection ends in, and not in a
    // destructor, which may run while the server's state is torn down.)
    void mark_closed() {
      closed_ = true;
      set_surface(false);
    }

    void read() {
      auto self = shared_from_this();
      ws_.async_read(buffer_, [self](beast::error_code ec, std::size_t) {
        if (ec) {
          self->mark_closed();
          if (ec == websocket::error::message_too_big)
            self->server_.drop(fmt::format("a message over {} bytes; session closed", self->server_.options.max_message));
          return;
        }
        const auto data = self->buffer_.cdata();
        const Parsed parsed =
            parse_control(std::span<const std::uint8_t>(static_cast<const std::uint8_t*>(data.data()), data.size()));
        self->buffer_.consume(self->buffer_.size());
        if (parsed.control) {
          ++self->server_.controls;
          if (const auto* surface = std::get_if<control::Surface>(&*parsed.control)) self->set_surface(surface->on);
          if (self->server_.on_control) self->server_.on_control(*parsed.control);
        } else {
          self->server_.drop(parsed.error);
        }
        self->read();
      });
    }

    Impl& server_;
    websocket::stream<beast::tcp_stream> ws_;
    beast::flat_buffer buffer_;
    std::deque<std::string> texts_;
    std::string text_;
    std::shared_ptr<const std::string> binary_;  // the frame or mesh being written
    std::uint64_t sent_seq_ = 0, sent_mesh_seq_ = 0;
    bool writing_ = false, closed_ = false, surface_ = false, last_was_frame_ = false;
  };

  class HttpSession : public std::enable_shared_from_this<HttpSession> {
   public:
    HttpSession(Impl& server, tcp::socket socket) : server_(server), stream_(std::move(socket)) {}

    void start() {
      parser_.emplace();
      parser_->body_limit(4096);
      stream_.expires_after(std::chrono::seconds(30));
      auto self = shared_from_this();
      http::async_read(stream_, buffer_, *parser_, [self](beast::error_code ec, std::size_t) {
        if (!ec) self->respond(self->parser_->release());
      });
    }

   private:
    void respond(http::request<http::string_body> request) {
      const auto raw = request.target();
      const Target target = split_target(std::string_view(raw.data(), raw.size()));
      if (!server_.options.token.empty() && target.token != server_.options.token)
        return reply(request, http::status::forbidden, "text/plain", "swirl view: a token is required\n");
      if (target.path == "/ws" && websocket::is_upgrade(request)) {
        auto session = std::make_shared<WsSession>(server_, stream_.release_socket());
        session->start(std::move(request));
        return;
      }
      if (request.method() != http::verb::get)
        return reply(request, http::status::method_not_allowed, "text/plain", "GET only\n");
      if (target.path == "/" || target.path == "/index.html")
        return reply(request, http::status::ok, "text/html; charset=utf-8", web::kIndexHtml);
      if (target.path == "/viewer.js")
        return reply(request, http::status::ok, "text/javascript; charset=utf-8", web::kViewerJs);
      reply(request, http::status::not_found, "text/plain", "not found\n");
    }

    void reply(const http::request<http::string_body>& request, http::status status, std::string_view type,
               std::string_view body) {
      auto response = std::make_shared<http::response<http::string_body>>(status, request.version());
      response->set(http::field::server, "swirl view");
      response->set(http::field::content_type, std::string(type));
      response->set(http::field::cache_control, "no-store");
      response->body() = std::string(body);
      response->keep_alive(false);
      response->prepare_payload();
      auto self = shared_from_this();
      http::async_write(stream_, *response, [self, response](beast::error_code, std::size_t) {
        beast::error_code ignored;
        self->stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
      });
    }

    Impl& server_;
    beast::tcp_stream stream_;
    beast::flat_buffer buffer_;
    std::optional<http::request_parser<http::string_body>> parser_;
  };
};

void LiveServer::Impl::accept() {
  acceptor.async_accept([this](beast::error_code ec, tcp::socket socket) {
    if (ec == net::error::operation_aborted) return;
    if (!ec) std::make_shared<HttpSession>(*this, std::move(socket))->start();
    accept();
  });
}

LiveServer::LiveServer(ServerOptions options, std::function<void(const Control&)> on_control,
                       std::function<std::string()> hello, std::function<void(const std::string&)> log)
    : impl_(std::make_unique<Impl>()) {
  impl_->options = std::move(options);
  impl_->on_control = std::move(on_control);
  impl_->hello = std::move(hello);
  impl_->log = std::move(log);
}

LiveServer::~LiveServer() { stop(); }

void LiveServer::start() {
  Impl& s = *impl_;
  beast::error_code ec;
  const auto address = net::ip::make_address(s.options.host, ec);
  if (ec) throw std::runtime_error(fmt::format("swirl view: '{}' is not an IP address", s.options.host));
  const tcp::endpoint endpoint{address, s.options.port};
  s.acceptor.open(endpoint.protocol(), ec);
  if (!ec) s.acceptor.set_option(net::socket_base::reuse_address(true), ec);
  if (!ec) s.acceptor.bind(endpoint, ec);
  if (!ec) s.acceptor.listen(net::socket_base::max_listen_connections, ec);
  if (ec)
    throw std::runtime_error(fmt::format("swirl view: cannot listen on {}:{}: {}", s.options.host, s.options.port, ec.message()));
  s.bound_port = s.acceptor.local_endpoint().port();
  s.accept();
  s.thread = std::thread([&s] { s.ioc.run(); });
}

void LiveServer::stop() {
  if (!impl_ || !impl_->thread.joinable()) return;
  impl_->ioc.stop();
  impl_->thread.join();
}

std::uint16_t LiveServer::port() const { return impl_->bound_port; }

std::string LiveServer::url() const {
  const std::string host = impl_->options.host == "0.0.0.0" ? "127.0.0.1" : impl_->options.host;
  return fmt::format("http://{}:{}/{}", host, impl_->bound_port,
                     impl_->options.token.empty() ? "" : "?token=" + impl_->options.token);
}

void LiveServer::publish(std::shared_ptr<const std::string> frame) {
  {
    std::lock_guard lock(impl_->mutex);
    impl_->latest = std::move(frame);
    ++impl_->latest_seq;
  }
  net::post(impl_->ioc, [this] { impl_->pump_all(); });
}

void LiveServer::publish_mesh(std::shared_ptr<const std::string> mesh) {
  {
    std::lock_guard lock(impl_->mutex);
    if (impl_->surface_viewers.load() == 0) return;  // nobody wants it (any more)
    impl_->mesh = std::move(mesh);
    ++impl_->mesh_seq;
  }
  net::post(impl_->ioc, [this] { impl_->pump_all(); });
}

std::size_t LiveServer::surface_viewers() const { return impl_->surface_viewers.load(); }

void LiveServer::announce(std::string text) {
  net::post(impl_->ioc, [this, text = std::move(text)] {
    std::erase_if(impl_->sessions, [](const auto& s) { return s.expired(); });
    for (auto& w : impl_->sessions)
      if (auto s = w.lock()) s->send_text(text);
  });
}

ServerStats LiveServer::stats() const {
  return {impl_->frames_sent.load(), impl_->bytes_sent.load(), impl_->controls.load(), impl_->dropped.load(),
          impl_->session_count.load(), impl_->meshes_sent.load(), impl_->mesh_bytes_sent.load()};
}

}  // namespace swirl::view
