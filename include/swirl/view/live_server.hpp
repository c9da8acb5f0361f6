// LiveServer: the HTTP and WebSocket server of `swirl view` (Boost.Beast on
// one I/O thread of its own).
//
//   GET /            the page (web/index.html, compiled in: works offline)
//   GET /viewer.js   its script
//   GET /ws          upgrades to a WebSocket: the server sends a hello (text,
//                    JSON: the scene's name, the fields that can colour, the
//                    box) and then frames (view/wire.hpp), the page sends
//                    controls
// Every request must carry ?token=<token> when a token is set (listening
// beyond 127.0.0.1); without it the answer is 403.
//
// Frames: publish() stores the newest frame (one shared buffer, whatever the
// number of viewers) and wakes the sessions; a session sends the newest frame
// it has not sent whenever its previous write is done, so a slow viewer skips
// frames instead of queueing them, and the simulation thread never waits for
// the network. Surface meshes (publish_mesh) likewise, but only to the
// sessions whose viewer turned the surface on (the surface control, kept per
// session here; surface_viewers() counts them, so that a session makes
// meshes only while someone wants them), alternating with frames when both
// are new. A session that ends stops counting; when none wants meshes the
// stored one is dropped, so that a viewer turning the surface on later never
// gets a stale one. Controls: each message is checked (parse_control); a bad one
// is dropped and logged (rate-limited), the session stays open; a message over
// max_message bytes closes that session (Beast's read limit), nothing else.
// Several viewers at once, each with its own session.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "swirl/view/wire.hpp"

namespace swirl::view {

struct ServerOptions {
  std::string host = "127.0.0.1";
  std::uint16_t port = 0;       // 0: any free port (port() says which)
  std::string token;            // required in every URL when not empty
  std::size_t max_message = 1024;  // bytes a control message may have
  bool surface_on_connect = false;  // a new viewer starts with the surface on (swirl view --surface)
};

struct ServerStats {
  std::uint64_t frames_sent = 0, bytes_sent = 0, controls = 0, dropped = 0, sessions = 0;
  std::uint64_t meshes_sent = 0, mesh_bytes_sent = 0;
};

class LiveServer {
 public:
  // on_control runs on the server's thread for every valid control; hello()
  // makes the text each new session receives first; log receives one line per
  // event worth telling (a dropped message, a session's end).
  LiveServer(ServerOptions options, std::function<void(const Control&)> on_control, std::function<std::string()> hello,
             std::function<void(const std::string&)> log);
  ~LiveServer();
  LiveServer(const LiveServer&) = delete;
  LiveServer& operator=(const LiveServer&) = delete;

  // Binds and starts the I/O thread; throws std::runtime_error naming the
  // address when it cannot listen.
  void start();
  void stop();
  std::uint16_t port() const;
  // The URL a browser opens (with the token, if any).
  std::string url() const;

  // Thread-safe: the newest frame for every viewer.
  void publish(std::shared_ptr<const std::string> frame);
  // Thread-safe: the newest surface mesh, for the viewers that want one.
  void publish_mesh(std::shared_ptr<const std::string> mesh);
  // Thread-safe: how many viewers have the surface on now.
  std::size_t surface_viewers() const;
  // Thread-safe: a text message (JSON) to every viewer now, e.g. an error.
  void announce(std::string text);
  ServerStats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace swirl::view
