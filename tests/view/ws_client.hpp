// A WebSocket client of swirl view's server for the tests (Boost.Beast): a
// viewer that reads the hello, statuses, frames and surface meshes with a
// deadline, so that a test fails rather than hangs, and sends controls.
#pragma once

#include <chrono>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>

#include <boost/asio.hpp>
#include <boost/beast.hpp>
#include <boost/beast/websocket.hpp>

#include "swirl/view/wire.hpp"

namespace swirl::view::test {

namespace beast = boost::beast;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;

// One WebSocket, each read with a deadline (a test fails, never hangs).
class Viewer {
 public:
  explicit Viewer(std::uint16_t port) : ws_(ioc_) {
    tcp::resolver resolver(ioc_);
    beast::get_lowest_layer(ws_).connect(resolver.resolve("127.0.0.1", std::to_string(port)));
    ws_.handshake("127.0.0.1", "/ws");
  }
  // The next message: text (first) and its bytes; throws after 20 s.
  std::pair<bool, std::string> next() {
    using namespace std::chrono_literals;
    beast::flat_buffer buffer;
    beast::error_code result = net::error::timed_out;
    bool done = false;
    ws_.async_read(buffer, [&](beast::error_code ec, std::size_t) { result = ec, done = true; });
    ioc_.restart();
    ioc_.run_for(20s);
    if (!done) {
      beast::get_lowest_layer(ws_).cancel();
      ioc_.restart();
      ioc_.run();
      throw std::runtime_error("no message from the server within 20 s");
    }
    if (result) throw beast::system_error(result);
    return {ws_.got_text(), beast::buffers_to_string(buffer.data())};
  }
  // The next frame, skipping text messages and meshes; throws after 30 s.
  DecodedFrame frame() {
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (std::chrono::steady_clock::now() < until) {
      auto [text, data] = next();
      if (!text && !is_mesh(data)) return decode_frame(bytes(data));
    }
    throw std::runtime_error("no frame from the server within 30 s");
  }
  // The next surface mesh, skipping text messages and frames; throws after 30 s.
  DecodedMesh mesh() {
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (std::chrono::steady_clock::now() < until) {
      auto [text, data] = next();
      if (!text && is_mesh(data)) return decode_mesh(bytes(data));
    }
    throw std::runtime_error("no surface mesh from the server within 30 s");
  }
  static bool is_mesh(const std::string& data) { return data.rfind("SWVM", 0) == 0; }
  static std::span<const std::uint8_t> bytes(const std::string& data) {
    return {reinterpret_cast<const std::uint8_t*>(data.data()), data.size()};
  }
  // The next status message's text.
  std::string status() {
    for (;;) {
      auto [text, data] = next();
      if (text && data.find("\"status\"") != std::string::npos) return data;
    }
  }
  void send(const std::string& bytes, bool text = false) {
    ws_.text(text);
    ws_.write(net::buffer(bytes));
  }
  // Reads until the server closes the session (true) or 20 s pass (false).
  bool closed_by_server() {
    try {
      for (;;) next();
    } catch (const beast::system_error&) {
      return true;
    } catch (const std::runtime_error&) {
      return false;
    }
  }

 private:
  net::io_context ioc_;
  websocket::stream<beast::tcp_stream> ws_;
};

// The next text message of a type ("status", "refused", ...), skipping the others and frames.
inline std::string next_text(Viewer& v, const std::string& type) {
  for (;;) {
    auto [text, data] = v.next();
    if (text && data.find("\"type\":\"" + type + "\"") != std::string::npos) return data;
  }
}

// A number in a JSON text after "key": (0 when absent).
inline double json_number_at(const std::string& json, const std::string& key) {
  const auto at = json.find("\"" + key + "\":");
  return at == std::string::npos ? 0.0 : std::stod(json.substr(at + key.size() + 3));
}

}  // namespace swirl::view::test
