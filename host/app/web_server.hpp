#pragma once
// The live view's server (civetweb): one page, embedded in the binary, at "/", and one
// WebSocket at "/ws" that carries the newest frames and measures out and commands in. Nothing
// else is served: no file is ever read from disk. Each viewer has a thread of its own that
// sends the newest frame when the last has gone out, so a slow or stalled viewer drops frames
// and holds at most one, and never holds up the run or another viewer (docs/serve.md).
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "app/live_run.hpp"

struct mg_context;
struct mg_connection;

namespace pbflow {

struct ServerLimits {
  int viewers = 16;                  // WebSocket connections at once; one more is refused
  int connections = 64;              // civetweb's worker threads: connections served at once
  size_t max_message = 4096;         // bytes of a command; a longer message closes its connection
  int request_timeout_ms = 10000;    // a request (or a frame's send) that takes longer is dropped
};

class WebServer {
 public:
  // Listens on `listen` ("127.0.0.1:8080"); throws InputError where it cannot (a bad address,
  // a port in use).
  WebServer(const std::string& listen, LiveRun& run, ServerLimits limits = {});
  ~WebServer();  // closes every connection and joins every viewer
  WebServer(const WebServer&) = delete;
  WebServer& operator=(const WebServer&) = delete;

  int port() const { return port_; }
  // Where the server listens beyond this machine: the token a viewer there must send with a
  // command to steer ({"cmd": ..., "token": ...}); empty on loopback, where anyone may.
  const std::string& token() const { return token_; }

 private:
  struct Viewer;
  static int page(mg_connection* conn, void* self);
  static int ws_connect(const mg_connection* conn, void* self);
  static void ws_ready(mg_connection* conn, void* self);
  static int ws_data(mg_connection* conn, int bits, char* data, size_t length, void* self);
  static void ws_close(const mg_connection* conn, void* self);
  void send_frames(Viewer& viewer);
  std::string answer(const char* data, size_t length, Viewer& viewer);  // a command's reply; empty: none

  LiveRun& run_;
  ServerLimits limits_;
  mg_context* ctx_ = nullptr;
  int port_ = 0;
  std::string token_;
  std::mutex viewers_mutex_;
  std::list<std::shared_ptr<Viewer>> viewers_;  // the connected viewers: at most limits_.viewers
};

}  // namespace pbflow
