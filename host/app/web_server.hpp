#pragma once
// The live view's server (Boost.Beast over Asio, on one thread of its own): one page, embedded
// in the binary, at "/", and one WebSocket at "/ws" that carries the newest frames and measures
// out and commands in. Nothing else is served: no file is ever read from disk. Every byte from
// a client is bounded before it is held (a request's head; a command's size, read from its
// frame header before its payload) and checked before it is used (UTF-8, masking, JSON); a
// viewer whose send stalls is closed, never sent a cut frame; only the server's own page may
// open the socket (docs/serve.md, "A server that trusts no client").
#include <memory>
#include <string>

#include "app/live_run.hpp"

namespace pbflow {

struct ServerLimits {
  int viewers = 16;                // WebSocket connections at once; one more is refused (503)
  int connections = 64;            // connections served at once; more wait in the listen queue
  size_t max_head = 16384;         // bytes of a request's head; more: 431, closed
  size_t max_message = 4096;       // bytes of a command, all its fragments; more: closed (1009), unread
  int request_timeout_ms = 10000;  // a request, a handshake or one send that takes longer: closed
  size_t max_replies = 8;          // replies waiting for a viewer; more are dropped
};

// Where `serve` listens: one numeric address and port, bound before the scene's set-up so that
// a port in use is said at once.
class Listener {
 public:
  // `text`: "ADDRESS:PORT", an IPv4 address or a bracketed IPv6 one, the port 0 (any free one)
  // to 65535. InputError naming the problem: anything else, or an address that cannot be bound.
  explicit Listener(const std::string& text);
  ~Listener();
  Listener(Listener&&) noexcept;
  Listener& operator=(Listener&&) noexcept;

 private:
  friend class WebServer;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

class WebServer {
 public:
  // Serves `run` on what `listener` bound, from now. A listener beyond loopback makes a token.
  WebServer(Listener listener, LiveRun& run, ServerLimits limits = {});
  // Closes every connection; once it returns, nothing of the server touches `run`.
  ~WebServer();
  WebServer(const WebServer&) = delete;
  WebServer& operator=(const WebServer&) = delete;

  int port() const;
  // What a viewer sends with each steering command ({"cmd": ..., "token": ...}) where the
  // server listens beyond loopback; empty on loopback, where anyone may steer.
  const std::string& token() const;

  struct Impl;  // web_server.cpp's

 private:
  std::shared_ptr<Impl> impl_;
};

}  // namespace pbflow
