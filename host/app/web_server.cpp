#include "app/web_server.hpp"

// Beast's string views are the standard's.
#define BOOST_BEAST_USE_STD_STRING_VIEW
#include <array>
#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <cmath>
#include <cstring>
#include <deque>
#include <list>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <sstream>
#include <thread>

#include "capture/renderer.hpp"
#include "capture/stream/h264.hpp"
#include "common/input_error.hpp"
#include "common/json_input.hpp"
#include "scene/parse.hpp"

namespace pbflow {

const std::vector<std::pair<std::string_view, std::string_view>>& web_pages_text();  // generated

namespace {

namespace net = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = net::ip::tcp;
using nlohmann::json;
using Clock = std::chrono::steady_clock;
using Request = http::request<http::string_body>;

constexpr size_t kMaxBody = 1024;  // a request's body: the page and the socket take none

// JSON as the server sends it. A client's bytes can reach a message (a parse error quotes
// what it last read, cut wherever the error fell): any that are not UTF-8 become U+FFFD
// instead of throwing.
std::string text_of(const json& j) { return j.dump(-1, ' ', false, json::error_handler_t::replace); }

std::string error_message(const std::string& text) { return text_of({{"type", "error"}, {"message", text}}); }

// At most `n` bytes of UTF-8 `s`, cut before a character, never inside one.
std::string clipped(const std::string& s, size_t n) {
  if (s.size() <= n) return s;
  while (n > 0 && (static_cast<unsigned char>(s[n]) & 0xC0) == 0x80) --n;
  return s.substr(0, n);
}

std::string page_text() {
  for (const auto& [name, text] : web_pages_text())
    if (name == "live") return std::string(text);
  return "";
}

json measures(const FrameStats& s) {
  return {{"mean_compression", s.mean_compression}, {"max_compression", s.max_compression},
          {"kinetic_energy", s.kinetic_energy},     {"potential_energy", s.potential_energy},
          {"solid_work", s.solid_work},             {"step_ms", s.step_ms},
          {"particles", s.count},                   {"emitted", s.emitted},
          {"drained", s.drained}};
}

json vector_json(const glm::dvec3& v) { return {v.x, v.y, v.z}; }

// What the page needs to drag the obstacles (LiveSolid) and show the tank's shaking.
void add_solids(json& m, const LiveFrame& f) {
  m["solids"] = json::array();
  for (const LiveSolid& s : f.solids)
    m["solids"].push_back({{"centre", vector_json(s.centre)}, {"screen", {s.screen.x, s.screen.y}},
                           {"radius", s.radius}, {"span", s.span}, {"body", s.body}});
  m["right"] = vector_json(f.right);
  m["up"] = vector_json(f.up);
  m["shake"] = f.shake.moves() ? json{{"axis", vector_json(f.shake.axis)}, {"amplitude", f.shake.amplitude},
                                      {"period", f.shake.period}}
                               : json();
  m["tilt"] = f.tilt.degrees != 0 ? json{{"axis", vector_json(f.tilt.axis)}, {"angle", f.tilt.degrees}} : json();
  m["emitters"] = f.emitters;
  m["emitting"] = f.emitters > 0 ? json(f.emitting) : json();
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
  add_solids(m, f);
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
  return text_of(m);
}

// A token a client must send to steer where the server listens beyond loopback: 128 random bits in hex.
std::string new_token() {
  std::random_device random;
  std::ostringstream hex;
  for (int i = 0; i < 4; ++i) hex << std::hex << random();
  return hex.str();
}

// "127.0.0.1:8080", "localhost", "[::1]:8080": whether a Host header names this machine.
bool loopback_name(std::string_view host) {
  std::string name(host);
  if (!name.empty() && name.front() == '[') {
    name = name.substr(1, name.find(']') == std::string::npos ? 0 : name.find(']') - 1);
  } else if (const size_t colon = name.rfind(':'); colon != std::string::npos) {
    name.resize(colon);
  }
  for (char& c : name) c = char(std::tolower(static_cast<unsigned char>(c)));
  boost::system::error_code error;
  const net::ip::address address = net::ip::make_address(name, error);
  return name == "localhost" || (!error && address.is_loopback());
}

// "ADDRESS:PORT": one numeric address (IPv6 in brackets) and a port, nothing else.
tcp::endpoint parse_listen(const std::string& text) {
  const InputError usage("--listen takes one ADDRESS:PORT, e.g. 127.0.0.1:8080 or [::1]:8080, not '" + text + "'");
  const size_t colon = text.rfind(':');
  if (colon == std::string::npos) throw usage;
  std::string host = text.substr(0, colon);
  const std::string port = text.substr(colon + 1);
  if (host.size() > 2 && host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
  else if (host.find(':') != std::string::npos) throw usage;
  if (port.empty() || port.size() > 5 || port.find_first_not_of("0123456789") != std::string::npos ||
      std::stoi(port) > 65535)
    throw usage;
  boost::system::error_code error;
  const net::ip::address address = net::ip::make_address(host, error);
  if (error) throw usage;
  return {address, static_cast<unsigned short>(std::stoi(port))};
}

}  // namespace

struct Listener::Impl {
  std::unique_ptr<net::io_context> io = std::make_unique<net::io_context>(1);
  tcp::acceptor acceptor{*io};
};

Listener::Listener(const std::string& text) : impl_(std::make_unique<Impl>()) {
  const tcp::endpoint endpoint = parse_listen(text);
  boost::system::error_code error;
  tcp::acceptor& a = impl_->acceptor;
  a.open(endpoint.protocol(), error);
  if (!error) a.set_option(net::socket_base::reuse_address(true), error);
  if (!error && endpoint.address().is_v6()) a.set_option(net::ip::v6_only(true), error);
  if (!error) a.bind(endpoint, error);
  if (!error) a.listen(net::socket_base::max_listen_connections, error);
  if (error) throw InputError("cannot listen on " + text + ": " + error.message());
}

Listener::~Listener() = default;
Listener::Listener(Listener&&) noexcept = default;
Listener& Listener::operator=(Listener&&) noexcept = default;

class Viewer;

// The server's state, touched only on its own thread (the pump and the run's thread post to it).
struct WebServer::Impl : std::enable_shared_from_this<WebServer::Impl> {
  Impl(Listener listener, LiveRun& r, ServerLimits l)
      : io(std::move(listener.impl_->io)), acceptor(std::move(listener.impl_->acceptor)), run(r), limits(l),
        port(acceptor->local_endpoint().port()), loopback(acceptor->local_endpoint().address().is_loopback()),
        token(loopback ? "" : new_token()), page(page_text()), retry(std::in_place, *io) {}
  // The Asio objects go before the context they were made on; the sessions its pending
  // handlers hold end with it, while the rest of the server's state is whole.
  ~Impl() {
    retry.reset();
    acceptor.reset();
    io.reset();
  }

  void accept();
  void ended() {  // a connection closed: its place is free
    --connections;
    if (!stopping) accept();
  }
  bool own_origin(const Request& request) const;
  std::string answer(const std::string& text, const std::shared_ptr<Viewer>& viewer);
  void publish(const std::shared_ptr<const LiveFrame>& frame);
  json hello() const;

  std::unique_ptr<net::io_context> io;
  std::optional<tcp::acceptor> acceptor;
  LiveRun& run;
  const ServerLimits limits;
  const int port;
  const bool loopback;
  const std::string token;
  const std::string page;
  std::optional<net::steady_timer> retry;  // after an accept that failed (out of descriptors): try again shortly
  int connections = 0;      // open: at most limits.connections
  bool accepting = false;
  int viewer_count = 0;     // WebSockets open or opening: at most limits.viewers
  std::list<std::weak_ptr<Viewer>> viewers;  // those whose handshake is done: they get frames
  std::atomic<bool> stopping{false};
  std::thread pump, thread;
};

namespace {

using Server = WebServer::Impl;

std::chrono::milliseconds request_timeout(const Server& s) { return std::chrono::milliseconds(s.limits.request_timeout_ms); }

// A connection's place among the server's limits.connections, held while it is open.
class Place {
 public:
  explicit Place(Server& server) : server_(&server) { ++server.connections; }
  ~Place() {
    if (server_) server_->ended();
  }
  Place(Place&& o) noexcept : server_(std::exchange(o.server_, nullptr)) {}
  Place(const Place&) = delete;
  Place& operator=(const Place&) = delete;
  Place& operator=(Place&&) = delete;

 private:
  Server* server_;
};

}  // namespace

// A viewer: one WebSocket. Commands in, read whole only when their frame headers say they fit;
// out, its replies, then the newest frame past the last it sent, then that frame's stats. A
// send that takes longer than the request timeout closes the connection: a frame is sent whole
// or the viewer gets nothing more.
class Viewer : public std::enable_shared_from_this<Viewer> {
 public:
  Viewer(beast::tcp_stream stream, Place place, Server& server)
      : ws_(std::move(stream)), place_(std::move(place)), server_(server), deadline_(ws_.get_executor()) {
    ++server_.viewer_count;
  }
  ~Viewer() {
    --server_.viewer_count;
    if (h264_) server_.run.count_h264_viewer(-1);
  }

  void accept(Request request) {
    request_ = std::move(request);
    ws_.read_message_max(server_.limits.max_message);  // checked from each frame's header, fragments summed
    ws_.auto_fragment(false);
    beast::get_lowest_layer(ws_).expires_never();  // the socket's own timeouts from here:
    ws_.set_option(websocket::stream_base::timeout{request_timeout(server_), websocket::stream_base::none(), false});
    ws_.async_accept(request_, [self = shared_from_this()](beast::error_code error) {
      if (error) return;
      self->server_.viewers.push_back(self);
      self->ready_ = true;
      self->reply(text_of(self->server_.hello()));
      self->offer(self->server_.run.next_frame(0, std::chrono::milliseconds(0)));  // the newest, at once
      self->read();
    });
  }
  void offer(std::shared_ptr<const LiveFrame> frame) {
    pending_ = std::move(frame);
    write_next();
  }
  void reply(std::string text) {
    if (texts_.size() < server_.limits.max_replies) texts_.push_back(std::move(text));  // a flood is answered in part
    write_next();
  }
  // The stream this viewer takes; false: JPEG.
  void take_h264(bool h264) {
    if (h264 != h264_) server_.run.count_h264_viewer(h264 ? 1 : -1);
    h264_ = h264;
  }

 private:
  void read() {
    ws_.async_read(in_, [self = shared_from_this()](beast::error_code error, size_t) {
      // Refused (past the limit, not UTF-8, unmasked, ...: Beast has sent the close frame that
      // says why) or closed: the viewer ends once its write is done.
      if (error) return self->close();
      const std::string reply = self->ws_.got_text()
                                    ? self->server_.answer(beast::buffers_to_string(self->in_.data()), self)
                                    : error_message("commands are JSON text messages (docs/serve.md)");
      self->in_.consume(self->in_.size());
      if (!reply.empty()) self->reply(reply);
      self->read();
    });
  }
  void write_next() {
    if (writing_ || !ready_ || closed_) return;
    if (!texts_.empty()) {
      text_ = std::move(texts_.front());
      texts_.pop_front();
      ws_.text(true);
      return write(net::buffer(text_), nullptr);
    }
    while (pending_) {
      std::shared_ptr<const LiveFrame> frame = std::exchange(pending_, nullptr);
      if (const std::string* payload = payload_of(*frame)) {
        ws_.text(false);
        return write(std::array<net::const_buffer, 2>{net::buffer(header_), net::buffer(*payload)}, frame);
      }
    }
  }
  // What this viewer is sent of `frame` (the 24-byte header filled in), or none: an H.264
  // viewer that joined or missed a unit waits for the next keyframe, which it asks for.
  const std::string* payload_of(const LiveFrame& frame) {
    uint32_t kind = 0;
    const std::string* payload = &frame.jpeg;
    if (h264_ && server_.run.h264_available()) {
      if (frame.unit == 0) return nullptr;  // the stream starts with the encoder's next frame
      const bool in_sequence = last_unit_ != 0 && frame.unit == last_unit_ + 1;
      if (!in_sequence && !frame.keyframe) {
        last_unit_ = 0;
        server_.run.request_keyframe();
        return nullptr;
      }
      last_unit_ = frame.unit;
      kind = frame.keyframe ? 1 : 2;
      payload = &frame.h264;
    }
    // The frame's number, when it was drawn (ms since the Unix epoch), what follows (0: a JPEG,
    // 1: an H.264 keyframe, 2: an H.264 delta frame) and 4 bytes of padding; then the payload.
    header_.fill(0);
    std::memcpy(header_.data(), &frame.number, 8);
    std::memcpy(header_.data() + 8, &frame.drawn_unix_ms, 8);
    std::memcpy(header_.data() + 16, &kind, 4);
    return payload;
  }
  // One message out, whole or the connection closed; after a frame, its stats.
  template <typename Buffers>
  void write(const Buffers& buffers, std::shared_ptr<const LiveFrame> frame) {
    writing_ = true;
    deadline_.expires_after(request_timeout(server_));
    deadline_.async_wait([weak = weak_from_this()](beast::error_code error) {
      // Past the deadline of the write in flight: one that ended as this fired set another.
      auto self = weak.lock();
      if (self && !error && self->writing_ && self->deadline_.expiry() <= net::steady_timer::clock_type::now())
        self->close();
    });
    const Clock::time_point began = Clock::now();
    const size_t bytes = net::buffer_size(buffers) - (frame ? header_.size() : 0);
    ws_.async_write(buffers, [self = shared_from_this(), frame, began, bytes](beast::error_code error, size_t) {
      self->writing_ = false;
      self->deadline_.cancel();
      if (error) return self->close();
      if (frame)
        self->texts_.push_front(
            stats_message(*frame, bytes, std::chrono::duration<double, std::milli>(Clock::now() - began).count()));
      self->write_next();
    });
  }
  void close() {
    if (closed_) return;
    closed_ = true;
    deadline_.cancel();
    beast::get_lowest_layer(ws_).close();  // what is pending ends with an error: the last hold goes
  }

  websocket::stream<beast::tcp_stream> ws_;
  Place place_;
  Server& server_;
  Request request_;            // the upgrade, held until the handshake is answered
  beast::flat_buffer in_;      // one command: at most limits.max_message
  std::deque<std::string> texts_;  // replies, and the stats of the frame last sent
  std::string text_;           // the text being written
  std::array<char, 24> header_{};  // the frame being written's
  std::shared_ptr<const LiveFrame> pending_;  // the newest frame not yet sent
  net::steady_timer deadline_;
  bool ready_ = false, writing_ = false, closed_ = false, h264_ = false;
  uint64_t last_unit_ = 0;     // the H.264 unit last sent; 0: waits for a keyframe
};

namespace {

// One HTTP request on a new connection: the page, a refusal, or a WebSocket handed to a Viewer.
// Its head is read with a limit and a deadline; any answer closes the connection.
class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(tcp::socket socket, Place place, Server& server)
      : stream_(std::move(socket)), place_(std::move(place)), server_(server),
        buffer_(server.limits.max_head + kMaxBody) {}

  void start() {
    parser_.header_limit(uint32_t(server_.limits.max_head));
    parser_.body_limit(kMaxBody);
    stream_.expires_after(request_timeout(server_));
    http::async_read(stream_, buffer_, parser_, [self = shared_from_this()](beast::error_code error, size_t) {
      self->on_request(error);
    });
  }

 private:
  void on_request(beast::error_code error) {
    if (error == http::error::end_of_stream || error == beast::error::timeout) return;  // closed or idle
    if (error == http::error::header_limit || error == http::error::buffer_overflow)
      return answer(http::status::request_header_fields_too_large, "the request's head is over its limit");
    if (error == http::error::body_limit) return answer(http::status::payload_too_large, "no body is taken");
    if (error) return answer(http::status::bad_request, "a malformed request");
    route(parser_.release());
  }

  void route(Request request) {
    if (request.version() != 10 && request.version() != 11)
      return answer(http::status::http_version_not_supported, "HTTP/1.0 or 1.1 only");
    const std::string_view target = request.target().substr(0, request.target().find('?'));
    if (target == "/ws") return upgrade(std::move(request));
    if (target != "/") return answer(http::status::not_found, "only / and /ws are served");
    const bool head = request.method() == http::verb::head;
    if (request.method() != http::verb::get && !head) return answer(http::status::method_not_allowed, "only GET");
    auto page = std::make_shared<http::response<http::string_body>>(http::status::ok, request.version());
    page->set(http::field::content_type, "text/html; charset=utf-8");
    page->set(http::field::cache_control, "no-store");
    // No other page may frame this one and steer it through a viewer's clicks.
    page->set(http::field::x_frame_options, "DENY");
    page->set("Content-Security-Policy", "frame-ancestors 'none'");
    page->body() = server_.page;
    page->prepare_payload();
    if (head) page->body().clear();
    send(page);
  }

  void upgrade(Request request) {
    if (!websocket::is_upgrade(request)) return answer(http::status::bad_request, "/ws takes a WebSocket upgrade");
    if (!server_.own_origin(request))
      return answer(http::status::forbidden, "only the page this server serves may open its socket");
    if (server_.viewer_count >= server_.limits.viewers)
      return answer(http::status::service_unavailable, "the viewer limit is reached");
    std::make_shared<Viewer>(std::move(stream_), std::move(place_), server_)->accept(std::move(request));
  }

  void answer(http::status status, const std::string& why) {
    auto response = std::make_shared<http::response<http::string_body>>(status, 11);
    response->set(http::field::content_type, "text/plain; charset=utf-8");
    if (status == http::status::method_not_allowed) response->set(http::field::allow, "GET, HEAD");
    response->body() = why + "\n";
    response->prepare_payload();
    send(response);
  }

  void send(const std::shared_ptr<http::response<http::string_body>>& response) {
    response->keep_alive(false);
    http::async_write(stream_, *response, [self = shared_from_this(), response](beast::error_code, size_t) {
      beast::error_code ignored;
      self->stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
    });
  }

  beast::tcp_stream stream_;
  Place place_;
  Server& server_;
  beast::flat_buffer buffer_;
  http::request_parser<http::string_body> parser_;
};

}  // namespace

void WebServer::Impl::accept() {
  if (accepting || connections >= limits.connections || !acceptor->is_open()) return;  // full: the rest wait
  accepting = true;
  acceptor->async_accept([this](beast::error_code error, tcp::socket socket) {
    accepting = false;
    if (error == net::error::operation_aborted) return;
    if (error) {
      retry->expires_after(std::chrono::milliseconds(100));
      return retry->async_wait([this](beast::error_code e) {
        if (!e) accept();
      });
    }
    std::make_shared<HttpSession>(std::move(socket), Place(*this), *this)->start();
    accept();
  });
}

// A browser names the page that opens a socket in `Origin`; a script sends none. Only this
// server's page may: http(s)://HOST of the request's own Host, and on a loopback listen a HOST
// that names loopback, so that a page from another name resolved here (DNS rebinding) may not.
bool WebServer::Impl::own_origin(const Request& request) const {
  const auto origin = request.find(http::field::origin);
  if (origin == request.end()) return true;
  const std::string_view host = request[http::field::host];
  if (host.empty()) return false;
  const std::string_view o = origin->value();
  if (o != "http://" + std::string(host) && o != "https://" + std::string(host)) return false;
  return !loopback || loopback_name(host);
}

json WebServer::Impl::hello() const {
  json scenes = json::array();
  for (const BuiltinScene& scene : builtin_scenes()) scenes.push_back(scene.name);
  return {{"type", "hello"},
          {"about", run.description()},
          {"scenes", std::move(scenes)},
          {"panels", run.panels()},
          {"steer", token.empty() ? "anyone" : "token"},
          {"h264_codec", capture::H264Encoder::codec_string()}};
}

void WebServer::Impl::publish(const std::shared_ptr<const LiveFrame>& frame) {
  for (auto v = viewers.begin(); v != viewers.end();) {
    if (std::shared_ptr<Viewer> viewer = v->lock()) {
      viewer->offer(frame);
      ++v;
    } else {
      v = viewers.erase(v);
    }
  }
}

WebServer::WebServer(Listener listener, LiveRun& run, ServerLimits limits)
    : impl_(std::make_shared<Impl>(std::move(listener), run, limits)) {
  Impl& s = *impl_;
  net::post(*s.io, [&s] { s.accept(); });
  s.thread = std::thread([&s] { s.io->run(); });
  // Each frame the run encodes, offered to every viewer on the server's thread.
  s.pump = std::thread([&s] {
    for (uint64_t last = 0; !s.stopping;) {
      std::shared_ptr<const LiveFrame> frame = s.run.next_frame(last, std::chrono::milliseconds(100));
      if (!frame) continue;
      last = frame->number;
      net::post(*s.io, [&s, frame] { s.publish(frame); });
    }
  });
}

WebServer::~WebServer() {
  impl_->stopping = true;
  impl_->pump.join();
  impl_->io->stop();
  impl_->thread.join();
}

int WebServer::port() const { return impl_->port; }
const std::string& WebServer::token() const { return impl_->token; }

namespace {

// A command's number `key` within [lo, hi], `fallback` where it is left out.
double number(const json& message, const char* key, double fallback, double lo, double hi) {
  if (!message.contains(key)) return fallback;
  const json& v = message[key];
  if (!v.is_number() || !(v.get<double>() >= lo && v.get<double>() <= hi)) {
    std::ostringstream m;
    m << "'" << key << "' must be a number in [" << lo << ", " << hi << "]";
    throw InputError(m.str());
  }
  return v.get<double>();
}

// A command's three numbers `key`, each finite and within [lo, hi].
glm::dvec3 triple(const json& message, const char* key, double lo, double hi) {
  const json& v = message.value(key, json());
  glm::dvec3 out;
  const bool ok = v.is_array() && v.size() == 3 && std::all_of(v.begin(), v.end(), [&](const json& x) {
    return x.is_number() && x.get<double>() >= lo && x.get<double>() <= hi;
  });
  if (!ok) {
    std::ostringstream m;
    m << "'" << key << "' must be three numbers in [" << lo << ", " << hi << "]";
    throw InputError(m.str());
  }
  for (int i = 0; i < 3; ++i) out[i] = v[size_t(i)].get<double>();
  return out;
}

std::string text(const json& message, const char* key) {
  return message.value(key, json()).is_string() ? message[key].get<std::string>() : "";
}

// A command's unit "axis" ([1, 0, 0] where left out): InputError where it is no direction.
glm::dvec3 direction(const json& message) {
  const glm::dvec3 axis = message.contains("axis") ? triple(message, "axis", -1e6, 1e6) : glm::dvec3(1, 0, 0);
  if (glm::length(axis) < 1e-6) throw InputError("'axis' must be a direction, not zero");
  return glm::normalize(axis);
}

// The arguments of a command of c.kind into c, each checked: InputError names the first wrong.
void read_arguments(const json& message, const LiveRun& run, LiveCommand& c) {
  using Kind = LiveCommand::Kind;
  if ((c.kind == Kind::Setting || c.kind == Kind::Budget) && run.panels() > 1)
    throw InputError("each panel of --compare keeps its setting");
  if (c.kind == Kind::Setting) {
    c.setting.method = text(message, "method");
    if (c.setting.method != "pbf" && c.setting.method != "ldc") throw InputError("'method' must be \"pbf\" or \"ldc\"");
    const double iterations = number(message, "iterations", 2, 1, kMaxLiveIterations);
    if (iterations != std::floor(iterations)) throw InputError("'iterations' must be a whole number");
    c.setting.iterations = int(iterations);
  } else if (c.kind == Kind::Scene) {
    c.scene = text(message, "name");
    const std::vector<BuiltinScene> scenes = builtin_scenes();
    std::string names;
    for (const BuiltinScene& b : scenes) names += (names.empty() ? "" : ", ") + b.name;
    if (std::none_of(scenes.begin(), scenes.end(), [&](const BuiltinScene& b) { return b.name == c.scene; }))
      throw InputError("'name' must be a built-in scene: " + names);
    run.check_scene(c.scene);
  } else if (c.kind == Kind::Budget) {
    c.budget_ms = number(message, "ms", 0, 0, 10000);
  } else if (c.kind == Kind::Style) {
    c.style = text(message, "style");
    capture::parse_style(c.style);  // InputError naming the styles
  } else if (c.kind == Kind::Drag) {
    if (!message.contains("obstacle")) throw InputError("'obstacle' must be an obstacle's index (0, 1, ...)");
    const double k = number(message, "obstacle", 0, 0, 1e6);
    if (k != std::floor(k)) throw InputError("'obstacle' must be an obstacle's index (0, 1, ...)");
    c.obstacle = size_t(k);
    if (message.contains("release") && !message["release"].is_boolean()) throw InputError("'release' must be true or false");
    c.release = message.value("release", false);
    if (!c.release) c.position = triple(message, "position", -1e6, 1e6);
  } else if (c.kind == Kind::Shake) {
    c.axis = direction(message);
    c.amplitude = number(message, "amplitude", 0, 0, 1);
    c.period = number(message, "period", 0, 0.05, 60);
  } else if (c.kind == Kind::Tilt) {
    c.tilt = {number(message, "angle", 0, -kMaxTiltDegrees, kMaxTiltDegrees), direction(message)};
  } else if (c.kind == Kind::Emit) {
    if (!message.contains("on") || !message["on"].is_boolean()) throw InputError("'on' must be true or false");
    c.emitting = message["on"].get<bool>();
  } else if (c.kind == Kind::Camera) {
    c.orbit_x = number(message, "orbit_x", 0, -7, 7), c.orbit_y = number(message, "orbit_y", 0, -7, 7);
    c.zoom = number(message, "zoom", 1, 0.1, 10);
    c.pan_x = number(message, "pan_x", 0, -10, 10), c.pan_y = number(message, "pan_y", 0, -10, 10);
  }
}

}  // namespace

// A command's reply (empty: none). Nothing from the client leaves here as an exception.
std::string WebServer::Impl::answer(const std::string& text, const std::shared_ptr<Viewer>& viewer) try {
  json message;
  try {
    message = parse_user_json(text, "the command");
  } catch (const InputError& e) {
    return error_message(e.what());
  }
  if (!message.is_object() || !message.contains("cmd") || !message["cmd"].is_string())
    return error_message("a command is an object with a string 'cmd', e.g. {\"cmd\": \"pause\"}");
  const std::string cmd = message["cmd"].get<std::string>();
  if (cmd == "stream") {  // how this viewer takes its frames: not steering
    const json codec = message.value("codec", json());
    if (codec != "h264" && codec != "jpeg") return error_message("stream: 'codec' must be \"h264\" or \"jpeg\"");
    viewer->take_h264(codec == "h264");
    return "";
  }
  if (!token.empty() && message.value("token", json()) != json(token))
    return error_message("steering this server needs the token it printed ({\"cmd\": ..., \"token\": ...})");
  using Kind = LiveCommand::Kind;
  static const std::pair<const char*, Kind> kinds[] = {{"pause", Kind::Pause},     {"resume", Kind::Resume},
                                                       {"step", Kind::Step},       {"restart", Kind::Restart},
                                                       {"setting", Kind::Setting}, {"style", Kind::Style},
                                                       {"camera", Kind::Camera},   {"scene", Kind::Scene},
                                                       {"budget", Kind::Budget},   {"drag", Kind::Drag},
                                                       {"shake", Kind::Shake},     {"tilt", Kind::Tilt},
                                                       {"emit", Kind::Emit}};
  const auto kind = std::find_if(std::begin(kinds), std::end(kinds), [&](const auto& k) { return cmd == k.first; });
  if (kind == std::end(kinds))
    return error_message("unknown command '" + clipped(cmd, 40) +
                         "' (pause, resume, step, restart, setting, style, camera, scene, budget, drag, shake, tilt, emit, stream)");
  LiveCommand c{kind->second};
  try {
    read_arguments(message, run, c);
  } catch (const InputError& e) {
    return error_message(cmd + ": " + e.what());
  }
  // Where the run cannot take it (a scene that fails to load), the run goes on as it was and
  // this viewer is told, on the server's thread, if both are still there.
  c.refused = [server = weak_from_this(), weak = std::weak_ptr<Viewer>(viewer), cmd](const std::string& why) {
    if (std::shared_ptr<Impl> s = server.lock())
      net::post(*s->io, [weak, why = cmd + ": " + why] {
        if (std::shared_ptr<Viewer> v = weak.lock()) v->reply(error_message(why));
      });
  };
  run.command(std::move(c));
  return "";
} catch (const std::exception& e) {
  return error_message(std::string("the command could not be taken: ") + e.what());
}

}  // namespace pbflow
