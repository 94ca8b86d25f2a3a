#include "app/web_server.hpp"

#include <civetweb.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "common/input_error.hpp"
#include "capture/stream/h264.hpp"
#include "capture/renderer.hpp"
#include "common/json_input.hpp"
#include "scene/parse.hpp"

namespace pbflow {

const std::vector<std::pair<std::string_view, std::string_view>>& web_pages_text();  // generated

namespace {

using nlohmann::json;

bool loopback(const char* address) {
  return address && (std::strncmp(address, "127.", 4) == 0 || std::strcmp(address, "::1") == 0);
}

std::string page_text() {
  for (const auto& [name, text] : web_pages_text())
    if (name == "live") return std::string(text);
  return "";
}

json measures(const FrameStats& s) {
  return {{"mean_compression", s.mean_compression}, {"max_compression", s.max_compression},
          {"kinetic_energy", s.kinetic_energy},     {"potential_energy", s.potential_energy},
          {"step_ms", s.step_ms}};
}

// `bytes`: the viewer's payload of the frame (JPEG or H.264); `send_ms`: how long handing it
// to the viewer's socket took. The first panel's measures stand at the top level.
std::string stats_message(const LiveFrame& f, size_t bytes, double send_ms) {
  json m = measures(f.panels[0].stats);
  m.update({{"type", "stats"},
            {"frame", f.number},
            {"time", f.sim_time},
            {"paused", f.paused},
            {"scene", f.scene},
            {"about", f.about},
            {"setting", f.panels[0].setting.name()},
            {"substeps", f.panels[0].setting.substeps},
            {"realtime_factor", f.realtime_factor},
            {"simulate_ms", f.simulate_ms},
            {"draw_ms", f.draw_ms},
            {"encode_ms", f.encode_ms},
            {"send_ms", send_ms},
            {"bytes", bytes},
            {"budget_ms", f.budget_ms}});
  if (f.panels.size() > 1) {
    m["panels"] = json::array();
    for (const LivePanel& p : f.panels) {
      json panel = measures(p.stats);
      panel["setting"] = p.setting.name();
      m["panels"].push_back(std::move(panel));
    }
  }
  if (f.front) {
    m["front"] = json::array();
    for (const FrontPoint& p : *f.front)
      m["front"].push_back({{"setting", p.setting.name()}, {"substeps", p.setting.substeps},
                            {"simulate_ms", p.simulate_ms}, {"mean_compression", p.mean_compression}});
  }
  return m.dump();
}

std::string error_message(const std::string& text) { return json{{"type", "error"}, {"message", text}}.dump(); }

// A token a client outside this machine must send to steer: 128 random bits in hex.
std::string new_token() {
  std::random_device random;
  std::ostringstream hex;
  for (int i = 0; i < 4; ++i) hex << std::hex << random();
  return hex.str();
}

}  // namespace

struct WebServer::Viewer {
  mg_connection* conn = nullptr;  // set when the handshake is done (ws_ready)
  bool local;  // connected from a loopback address: may steer without the token
  std::atomic<bool> h264{false};  // takes the H.264 stream ({"cmd": "stream"}), else JPEG
  uint64_t last_unit = 0;         // the H.264 unit last sent; 0: waits for a keyframe
  std::atomic<bool> closed{false};
  std::mutex mutex;
  std::deque<std::string> replies;  // text messages for the sender, at most a few
  std::thread sender;
};

WebServer::WebServer(const std::string& listen, LiveRun& run, ServerLimits limits) : run_(run), limits_(limits) {
  mg_init_library(MG_FEATURES_WEBSOCKET);
  const std::string threads = std::to_string(limits.connections), timeout = std::to_string(limits.request_timeout_ms);
  const char* options[] = {"listening_ports", listen.c_str(), "num_threads", threads.c_str(), "request_timeout_ms",
                           timeout.c_str(), "enable_keep_alive", "no", "max_request_size", "16384", nullptr};
  mg_callbacks callbacks{};
  callbacks.log_message = [](const mg_connection*, const char*) { return 1; };  // errors reach the client, not stderr
  mg_init_data init{&callbacks, this, options};
  char error_text[256] = "";
  unsigned error_code = 0;
  mg_error_data error{&error_code, error_text, sizeof error_text};
  ctx_ = mg_start2(&init, &error);
  if (!ctx_) {
    mg_exit_library();
    throw InputError("cannot listen on " + listen + ": " + (error_text[0] ? error_text : "unknown error"));
  }
  mg_server_port ports[4]{};
  if (mg_get_server_ports(ctx_, 4, ports) > 0) port_ = ports[0].port;
  mg_set_request_handler(ctx_, "/$", &WebServer::page, this);
  mg_set_websocket_handler(ctx_, "/ws$", &WebServer::ws_connect, &WebServer::ws_ready, &WebServer::ws_data,
                           &WebServer::ws_close, this);
  if (!loopback(listen.c_str())) token_ = new_token();
}

WebServer::~WebServer() {
  mg_stop(ctx_);  // closes every connection; ws_close joins each viewer's thread
  mg_exit_library();
}

int WebServer::page(mg_connection* conn, void*) {
  const mg_request_info* request = mg_get_request_info(conn);
  if (std::strcmp(request->request_method, "GET") != 0 && std::strcmp(request->request_method, "HEAD") != 0) {
    mg_send_http_error(conn, 405, "%s", "only GET");
    return 405;
  }
  static const std::string text = page_text();
  mg_send_http_ok(conn, "text/html; charset=utf-8", (long long)text.size());
  if (std::strcmp(request->request_method, "GET") == 0) mg_write(conn, text.data(), text.size());
  return 200;
}

// An accepted connection gets its viewer here, in the list from here until ws_close: the list
// is the count the limit holds, and a refused connection is never in it.
int WebServer::ws_connect(const mg_connection* conn, void* self) {
  auto* server = static_cast<WebServer*>(self);
  std::lock_guard lock(server->viewers_mutex_);
  if (server->viewers_.size() >= size_t(server->limits_.viewers)) return 1;  // refused
  auto viewer = std::make_shared<Viewer>();
  viewer->local = loopback(mg_get_request_info(conn)->remote_addr);
  json scenes = json::array();
  for (const BuiltinScene& scene : builtin_scenes()) scenes.push_back(scene.name);
  viewer->replies.push_back(json{{"type", "hello"},
                                 {"about", server->run_.description()},
                                 {"scenes", std::move(scenes)},
                                 {"panels", server->run_.panels()},
                                 {"h264_codec", capture::H264Encoder::codec_string()}}
                                .dump());
  mg_set_user_connection_data(conn, viewer.get());
  server->viewers_.push_back(std::move(viewer));
  return 0;
}

void WebServer::ws_ready(mg_connection* conn, void* self) {
  auto* server = static_cast<WebServer*>(self);
  auto* viewer = static_cast<Viewer*>(mg_get_user_connection_data(conn));
  if (!viewer) return;
  viewer->conn = conn;
  viewer->sender = std::thread([server, viewer] { server->send_frames(*viewer); });
}

int WebServer::ws_data(mg_connection* conn, int bits, char* data, size_t length, void* self) {
  auto* server = static_cast<WebServer*>(self);
  auto* viewer = static_cast<Viewer*>(mg_get_user_connection_data(conn));
  const int opcode = bits & 0xf;
  if (opcode == MG_WEBSOCKET_OPCODE_CONNECTION_CLOSE || !viewer) return 0;
  if (opcode == MG_WEBSOCKET_OPCODE_PING || opcode == MG_WEBSOCKET_OPCODE_PONG) return 1;
  if (length > server->limits_.max_message) return 0;  // closes the connection
  std::string reply = opcode == MG_WEBSOCKET_OPCODE_TEXT
                          ? server->answer(data, length, *viewer)
                          : error_message("commands are JSON text messages (docs/serve.md)");
  if (!reply.empty()) {
    std::lock_guard lock(viewer->mutex);
    if (viewer->replies.size() < 8) viewer->replies.push_back(std::move(reply));  // a flood is answered in part
  }
  return 1;
}

void WebServer::ws_close(const mg_connection* conn, void* self) {
  auto* server = static_cast<WebServer*>(self);
  auto* viewer = static_cast<Viewer*>(mg_get_user_connection_data(conn));
  if (!viewer) return;  // refused at the handshake: never counted
  viewer->closed = true;
  if (viewer->sender.joinable()) viewer->sender.join();
  if (viewer->h264) server->run_.count_h264_viewer(-1);
  mg_set_user_connection_data(conn, nullptr);
  std::lock_guard lock(server->viewers_mutex_);
  server->viewers_.remove_if([&](const std::shared_ptr<Viewer>& v) { return v.get() == viewer; });
}

// A viewer's own thread: its replies, then the newest frame past the last it sent. A viewer
// that reads slowly gets fewer frames; one whose send fails or times out gets none after.
void WebServer::send_frames(Viewer& viewer) {
  uint64_t last = 0;
  auto send = [&](int opcode, const char* data, size_t size) {
    mg_lock_connection(viewer.conn);
    const int sent = mg_websocket_write(viewer.conn, opcode, data, size);
    mg_unlock_connection(viewer.conn);
    return sent > 0;
  };
  while (!viewer.closed) {
    std::deque<std::string> replies;
    {
      std::lock_guard lock(viewer.mutex);
      replies.swap(viewer.replies);
    }
    for (const std::string& r : replies)
      if (!send(MG_WEBSOCKET_OPCODE_TEXT, r.data(), r.size())) return;
    const std::shared_ptr<const LiveFrame> frame = run_.next_frame(last, std::chrono::milliseconds(100));
    if (!frame) continue;
    last = frame->number;
    // The frame's number, when it was drawn (ms since the Unix epoch), what follows (0: a JPEG,
    // 1: an H.264 keyframe, 2: an H.264 delta frame) and 4 bytes of padding; then the payload.
    uint32_t kind = 0;
    const std::string* payload = &frame->jpeg;
    if (viewer.h264 && run_.h264_available()) {
      if (frame->unit == 0) continue;  // the stream starts with the encoder's next frame
      const bool in_sequence = viewer.last_unit != 0 && frame->unit == viewer.last_unit + 1;
      if (!in_sequence && !frame->keyframe) {  // joined, or missed a unit: the next keyframe
        viewer.last_unit = 0;
        run_.request_keyframe();
        continue;
      }
      viewer.last_unit = frame->unit;
      kind = frame->keyframe ? 1 : 2;
      payload = &frame->h264;
    }
    std::string message(24, '\0');
    const uint64_t number = frame->number;
    std::memcpy(message.data(), &number, 8);
    std::memcpy(message.data() + 8, &frame->drawn_unix_ms, 8);
    std::memcpy(message.data() + 16, &kind, 4);
    message += *payload;
    const auto began = std::chrono::steady_clock::now();
    if (!send(MG_WEBSOCKET_OPCODE_BINARY, message.data(), message.size())) return;
    const double send_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - began).count();
    const std::string stats = stats_message(*frame, payload->size(), send_ms);
    if (!send(MG_WEBSOCKET_OPCODE_TEXT, stats.data(), stats.size())) return;
  }
}

std::string WebServer::answer(const char* data, size_t length, Viewer& viewer) {
  json message;
  try {
    message = parse_user_json(std::string_view(data, length), "the command");
  } catch (const InputError& e) {
    return error_message(e.what());
  }
  if (!message.is_object() || !message.contains("cmd") || !message["cmd"].is_string())
    return error_message("a command is an object with a string 'cmd', e.g. {\"cmd\": \"pause\"}");
  if (message["cmd"] == "stream") {  // how this viewer takes its frames: not steering
    const json codec = message.value("codec", json());
    if (codec != "h264" && codec != "jpeg") return error_message("stream: 'codec' must be \"h264\" or \"jpeg\"");
    const bool h264 = codec == "h264";
    if (viewer.h264.exchange(h264) != h264) run_.count_h264_viewer(h264 ? 1 : -1);
    return "";
  }
  if (!viewer.local && !token_.empty() && message.value("token", json()) != json(token_))
    return error_message("steering from another machine needs the token the server printed");
  const std::string cmd = message["cmd"].get<std::string>();
  auto number = [&](const char* key, double fallback, double lo, double hi) {
    if (!message.contains(key)) return fallback;
    const json& v = message[key];
    if (!v.is_number() || !(v.get<double>() >= lo && v.get<double>() <= hi)) {
      std::ostringstream m;
      m << "'" << key << "' must be a number in [" << lo << ", " << hi << "]";
      throw InputError(m.str());
    }
    return v.get<double>();
  };
  using Kind = LiveCommand::Kind;
  static const std::pair<const char*, Kind> kinds[] = {{"pause", Kind::Pause},     {"resume", Kind::Resume},
                                                       {"step", Kind::Step},       {"restart", Kind::Restart},
                                                       {"setting", Kind::Setting}, {"style", Kind::Style},
                                                       {"camera", Kind::Camera},   {"scene", Kind::Scene},
                                                       {"budget", Kind::Budget}};
  const auto kind = std::find_if(std::begin(kinds), std::end(kinds), [&](const auto& k) { return cmd == k.first; });
  if (kind == std::end(kinds))
    return error_message("unknown command '" + cmd.substr(0, 40) +
                         "' (pause, resume, step, restart, setting, style, camera, scene, budget, stream)");
  LiveCommand c{kind->second};
  try {
    if ((c.kind == Kind::Setting || c.kind == Kind::Budget) && run_.panels() > 1)
      throw InputError("each panel of --compare keeps its setting");
    if (c.kind == Kind::Setting) {
      c.setting.method = message.value("method", json()).is_string() ? message["method"].get<std::string>() : "";
      if (c.setting.method != "pbf" && c.setting.method != "ldc")
        throw InputError("'method' must be \"pbf\" or \"ldc\"");
      const double iterations = number("iterations", 2, 1, kMaxLiveIterations);
      if (iterations != std::floor(iterations)) throw InputError("'iterations' must be a whole number");
      c.setting.iterations = int(iterations);
    } else if (c.kind == Kind::Scene) {
      c.scene = message.value("name", json()).is_string() ? message["name"].get<std::string>() : "";
      const std::vector<BuiltinScene> scenes = builtin_scenes();
      std::string names;
      for (const BuiltinScene& b : scenes) names += (names.empty() ? "" : ", ") + b.name;
      if (std::none_of(scenes.begin(), scenes.end(), [&](const BuiltinScene& b) { return b.name == c.scene; }))
        throw InputError("'name' must be a built-in scene: " + names);
      run_.check_scene(c.scene);
    } else if (c.kind == Kind::Budget) {
      c.budget_ms = number("ms", 0, 0, 10000);
    } else if (c.kind == Kind::Style) {
      c.style = message.value("style", json()).is_string() ? message["style"].get<std::string>() : "";
      capture::parse_style(c.style);  // InputError naming the styles
    } else if (c.kind == Kind::Camera) {
      c.orbit_x = number("orbit_x", 0, -7, 7), c.orbit_y = number("orbit_y", 0, -7, 7);
      c.zoom = number("zoom", 1, 0.1, 10), c.pan_x = number("pan_x", 0, -10, 10), c.pan_y = number("pan_y", 0, -10, 10);
    }
  } catch (const InputError& e) {
    return error_message(cmd + ": " + e.what());
  }
  run_.command(c);
  return "";
}

}  // namespace pbflow
