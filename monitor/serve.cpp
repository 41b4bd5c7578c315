#include "marsala/monitor/serve.hpp"

#include <fmt/format.h>
#include <httplib.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <filesystem>
#include <limits>
#include <mutex>
#include <ostream>
#include <thread>

#include "marsala/cli/listen_problem.hpp"
#include "marsala/core/error.hpp"
#include "marsala/monitor/live_model.hpp"
#include "marsala/monitor/replay.hpp"
#include "marsala/monitor/web_assets.hpp"
#include "marsala/monitor/world_gate.hpp"
#include "marsala/protocol/end_reason.hpp"
#include "marsala/render/png_writer.hpp"
#include "marsala/render/terrain_renderer.hpp"
#include "marsala/runlog/run_log.hpp"
#include "marsala/scenario/scenario.hpp"
#include "marsala/terrain/asc_io.hpp"

namespace marsala::monitor {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

/// HTTP worker threads: each request is answered at once from the published documents, so a few threads serve many
/// pages; a page keeps at most one request (and its picture) in flight.
constexpr std::size_t kHttpThreads = 8;
/// A client that does not take its response within this long is cut off [s].
constexpr time_t kSocketTimeoutS = 5;
/// How often the follower looks for new records of a live run.log, and retries a folder it cannot read yet.
constexpr auto kFollowPoll = 100ms;
constexpr auto kRetryPoll = 500ms;
/// Records applied between two looks at the clock (a picture or the stop may be due) in a long backlog.
constexpr int kRecordsPerBatch = 5000;

const char* content_type(const std::string& name) {
  if (name.size() >= 5 && name.compare(name.size() - 5, 5, ".html") == 0) return "text/html; charset=utf-8";
  if (name.size() >= 3 && name.compare(name.size() - 3, 3, ".js") == 0) return "text/javascript; charset=utf-8";
  if (name.size() >= 4 && name.compare(name.size() - 4, 4, ".css") == 0) return "text/css; charset=utf-8";
  return "application/octet-stream";
}

/// The scene of the scenario whose text the log's header carries; none when it does not parse here (e.g. a terrain
/// file path that only resolves where the world ran: the overlays are left out, the terrain still shows).
std::optional<LiveScene> scene_of(const proto::LogHeader& header) {
  try {
    const scenario::Scenario s = scenario::parse_scenario(header.scenario_text(), header.scenario_file());
    LiveScene scene;
    scene.completion = scenario::to_string(s.completion);
    scene.base = s.base.centre;
    scene.base_radius_m = s.base.radius_m;
    switch (s.completion) {
      case scenario::CompletionKind::kAgentsAtGoal:
        scene.goal = s.goal.area;
        break;
      case scenario::CompletionKind::kLevelSite:
        scene.site = s.site.area;
        break;
      case scenario::CompletionKind::kPayloadPath:
        scene.payload = std::make_pair(s.payload_path.from, s.payload_path.to);
        break;
    }
    for (const scenario::AgentSlot& slot : s.slots)
      if (slot.id <= header.agents()) scene.targets.emplace_back(slot.id, slot.target);
    return scene;
  } catch (const Error&) {
    return std::nullopt;
  }
}

/// Steps in a finished log (for a replay's position); stops at a damaged tail.
std::uint64_t count_steps(const std::string& log_path) {
  runlog::RunLogReader reader(log_path);
  proto::LogRecord record;
  std::uint64_t steps = 0;
  while (reader.next(record))
    if (record.has_step()) ++steps;
  return steps;
}

}  // namespace

struct LiveServer::Impl {
  explicit Impl(ServeOptions o) : options(std::move(o)), model(source_name(options), !options.replay_dir.empty()) {}

  static std::string source_name(const ServeOptions& o) {
    return o.replay_dir.empty() ? std::string("DDS") : fmt::format("replay of {}", o.replay_dir);
  }

  ServeOptions options;
  httplib::Server http;

  std::mutex model_mutex;
  LiveModel model;
  std::atomic<bool> model_changed{true};

  std::mutex published_mutex;
  std::shared_ptr<const std::string> state_doc = std::make_shared<const std::string>("{}");
  std::shared_ptr<const std::string> terrain_png;

  std::mutex stop_mutex;
  std::condition_variable stop_cv;
  bool stopping = false;

  bool wait_stop_for(Clock::duration d) {
    std::unique_lock<std::mutex> lock(stop_mutex);
    return stop_cv.wait_for(lock, d, [&] { return stopping; });
  }
  bool stop_requested() {
    std::lock_guard<std::mutex> lock(stop_mutex);
    return stopping;
  }

  /// Rebuilds the state document from the model and swaps it in.
  void publish_state() {
    std::string doc;
    {
      std::lock_guard<std::mutex> lock(model_mutex);
      doc = model.state_json(Clock::now());
    }
    auto shared = std::make_shared<const std::string>(std::move(doc));
    std::lock_guard<std::mutex> lock(published_mutex);
    state_doc = std::move(shared);
  }

  std::shared_ptr<const std::string> current(const std::shared_ptr<const std::string>& which) {
    std::lock_guard<std::mutex> lock(published_mutex);
    return which;
  }

  void set_note(const std::string& note) {
    std::lock_guard<std::mutex> lock(model_mutex);
    model.set_map_note(note);
    model_changed = true;
  }

  void routes() {
    for (const WebAsset& asset : web_assets()) {
      const std::string path = std::string(asset.name) == "index.html" ? "/" : "/" + std::string(asset.name);
      const std::string* body = &asset.body;
      const char* type = content_type(asset.name);
      http.Get(path, [body, type](const httplib::Request&, httplib::Response& res) {
        res.set_header("Cache-Control", "no-cache");
        res.set_content(*body, type);
      });
    }
    http.Get("/api/state", [this](const httplib::Request&, httplib::Response& res) {
      const std::shared_ptr<const std::string> doc = current(state_doc);
      res.set_header("Cache-Control", "no-store");
      // The shared document stays alive as long as the response needs it; no copy per client.
      res.set_content_provider(
          doc->size(), "application/json",
          [doc](std::size_t offset, std::size_t length, httplib::DataSink& sink) {
            return sink.write(doc->data() + offset, std::min(length, doc->size() - offset));
          });
    });
    http.Get("/api/terrain.png", [this](const httplib::Request&, httplib::Response& res) {
      const std::shared_ptr<const std::string> png = current(terrain_png);
      if (!png) {
        res.status = 404;
        res.set_content("no terrain picture yet", "text/plain");
        return;
      }
      // Versioned by the page's query (?v=N): each version is immutable.
      res.set_header("Cache-Control", "max-age=3600");
      res.set_content_provider(png->size(), "image/png",
                               [png](std::size_t offset, std::size_t length, httplib::DataSink& sink) {
                                 return sink.write(png->data() + offset, std::min(length, png->size() - offset));
                               });
    });
  }

  /// Follows `dir`/run.log: as it grows (live), or at options.replay_steps_per_s from its start (replay, which also
  /// makes the statuses). Redraws the terrain picture when it changed, at most every terrain_interval_s.
  void follow(const std::string& dir, bool replay) {
    const std::string log_path = (fs::path(dir) / runlog::kRunLogFile).string();
    const std::string terrain_path = (fs::path(dir) / "terrain_initial.asc").string();
    std::unique_ptr<TerrainReplayer> replayer;
    std::optional<LiveScene> scene;
    std::string run_id;
    std::uint64_t offset = 0;
    std::uint64_t total_steps = 0;
    std::uint64_t picture_version = 0;
    bool picture_due = false;
    bool log_over = false;
    Clock::time_point started;
    Clock::time_point last_picture;
    const auto picture_interval = std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(options.terrain_interval_s));

    while (!stop_requested()) {
      if (!replayer) {
        try {
          if (!fs::exists(log_path)) throw IoError(fmt::format("waiting for {}", log_path));
          runlog::RunLogReader reader(log_path);
          Heightmap initial = terrain::read_asc(terrain_path);
          check_initial_terrain(reader.header(), initial, terrain_path);
          scene = scene_of(reader.header());
          run_id = reader.header().run_id();
          replayer = std::make_unique<TerrainReplayer>(reader.header(), std::move(initial), log_path);
          offset = reader.first_record_offset();
          total_steps = replay ? count_steps(log_path) : 0;
          picture_due = true;
          log_over = false;
          started = Clock::now();
          last_picture = Clock::time_point{};
        } catch (const Error& e) {
          // A run that has not written its log or terrain yet (or a half-written header): try again.
          set_note(e.what());
          wait_stop_for(kRetryPoll);
          continue;
        }
      }
      std::optional<runlog::RunLogReader> reader;
      try {
        reader.emplace(log_path);
        if (reader->header().run_id() != run_id || reader->file_bytes() < offset)
          throw IoError(fmt::format("{} now holds another run", log_path));
        reader->seek(offset);
      } catch (const Error& e) {
        replayer.reset();  // the folder was cleared or another run took it over: start again
        set_note(e.what());
        continue;
      }
      bool applied = false;
      try {
        proto::LogRecord record;
        for (int n = 0; n < kRecordsPerBatch; ++n) {
          if (replay) {
            const double due = std::chrono::duration<double>(Clock::now() - started).count() *
                               options.replay_steps_per_s;
            if (static_cast<double>(replayer->steps()) >= due) break;
          }
          const std::uint64_t at = reader->offset();
          if (!reader->next(record)) {
            log_over = replay;  // a live log grows on; a replayed one ends here (or at its damaged tail)
            break;
          }
          replayer->apply(record, at);
          offset = reader->offset();
          applied = true;
        }
      } catch (const Error& e) {
        // The log disagrees with the replay of itself: show why and stop following.
        set_note(fmt::format("stopped following the run log: {}", e.what()));
        wait_stop_for(std::chrono::hours(24 * 365));
        return;
      }
      if (replay && (applied || log_over)) {
        const protocol::WorldStatus status = replay_status(*replayer, total_steps, started, log_over);
        std::lock_guard<std::mutex> lock(model_mutex);
        model.on_status(status, Clock::now());
        model_changed = true;
      }
      picture_due = picture_due || applied;
      if (picture_due && Clock::now() - last_picture >= picture_interval) {
        draw(*replayer, scene, ++picture_version);
        last_picture = Clock::now();
        picture_due = false;
      }
      if (log_over && !picture_due) {
        wait_stop_for(std::chrono::hours(24 * 365));
        return;
      }
      wait_stop_for(replay ? Clock::duration(20ms) : Clock::duration(kFollowPoll));
    }
  }

  /// A WorldStatus made from a replay: step, volume, agents (position = target of the latest accepted move; material
  /// is not in the log) and the replay's position in the log as progress.
  static protocol::WorldStatus replay_status(const TerrainReplayer& r, std::uint64_t total_steps, Clock::time_point started, bool over) {
    protocol::WorldStatus s;
    s.run_id = r.header().run_id();
    s.scenario = r.header().scenario();
    s.step = r.steps();
    s.wall_seconds = std::chrono::duration<double>(Clock::now() - started).count();
    s.deposited_volume_m3 = r.deposited_volume_m3();
    s.progress = total_steps > 0 ? std::min(1.0, static_cast<double>(r.steps()) / static_cast<double>(total_steps))
                                 : 0.0;
    s.running = !over;
    s.completed = over && r.run_end() && protocol::find_end_reason(r.run_end()->end_reason()) == protocol::EndReason::kCompleted;
    for (const auto& [id, a] : r.agents()) {
      if (id == 0 || !a.admitted) continue;
      protocol::AgentStatus as;
      as.agent_id = id;
      as.name = a.name;
      as.state = a.state;
      if (a.position) {
        as.x_m = a.position->x;
        as.y_m = a.position->y;
        const std::optional<CellIndex> cell = r.terrain().geometry().cell_at(*a.position);
        if (cell && r.terrain().contains(*cell)) as.z_m = r.terrain()(cell->row, cell->col);
      }
      as.material_m3 = std::numeric_limits<double>::quiet_NaN();  // not in the log: the page shows "-"
      as.deposited_m3 = a.deposited_m3;
      as.accepted = static_cast<std::uint32_t>(a.accepted);
      as.rejected = static_cast<std::uint32_t>(a.rejected);
      as.alive = !a.dropped;
      s.agents.push_back(as);
    }
    return s;
  }

  void draw(const TerrainReplayer& r, const std::optional<LiveScene>& scene, std::uint64_t version) {
    render::RenderOptions o;
    o.legend = false;
    o.max_size_px = options.max_picture_px;
    if (r.depositor().size() > 0 && r.depositor().maxCoeff() > 0) o.labels = r.depositor();
    const render::Image image = render::render_terrain(r.terrain(), o);
    const std::vector<std::uint8_t> bytes = render::encode_png(image, render::PngSpeed::kFast);
    auto png = std::make_shared<const std::string>(bytes.begin(), bytes.end());
    LiveMap map;
    map.geometry = r.terrain().geometry();
    map.min_height_m = r.terrain().min_height();
    map.max_height_m = r.terrain().max_height();
    map.image_width_px = image.width;
    map.image_height_px = image.height;
    map.version = version;
    map.log_steps = r.steps();
    map.scene = scene;
    {
      std::lock_guard<std::mutex> lock(published_mutex);
      terrain_png = std::move(png);
    }
    std::lock_guard<std::mutex> lock(model_mutex);
    model.set_map(map);
    model_changed = true;
  }
};

LiveServer::LiveServer(ServeOptions options) : impl_(std::make_unique<Impl>(std::move(options))) {
  const ServeOptions& o = impl_->options;
  if (o.port < 1 || o.port > 65535)
    throw InvalidArgument(fmt::format("--port {}: must be a TCP port, 1..65535", o.port));
  if (!(o.replay_steps_per_s > 0.0)) throw InvalidArgument("--speed must be > 0 steps/s");
  if (!o.replay_dir.empty() && !fs::is_directory(o.replay_dir))
    throw InvalidArgument(fmt::format("--replay {}: not a folder", o.replay_dir));
  if (!o.replay_dir.empty() && !fs::exists(fs::path(o.replay_dir) / runlog::kRunLogFile))
    throw InvalidArgument(fmt::format("--replay {}: holds no {}", o.replay_dir, runlog::kRunLogFile));
  Impl& impl = *impl_;
  impl.routes();
  impl.http.new_task_queue = [] { return new httplib::ThreadPool(kHttpThreads); };
  // One request per connection: a page polls one request at a time, so a kept-alive connection would tie a worker
  // to one page between its polls; reconnecting on loopback costs far less than starving other pages.
  impl.http.set_keep_alive_max_count(1);
  impl.http.set_read_timeout(kSocketTimeoutS, 0);
  impl.http.set_write_timeout(kSocketTimeoutS, 0);
  impl.http.set_payload_max_length(1 << 16);
  if (!impl.http.bind_to_port(o.bind_address, o.port))
    throw ListenError(
        fmt::format("cannot listen on {} port {}: {}", o.bind_address, o.port, cli::listen_problem(o.bind_address, o.port)));
}

LiveServer::~LiveServer() = default;

int LiveServer::port() const { return impl_->options.port; }

int LiveServer::run(bus::Participant* participant, const StopSource& stop, std::ostream& out) {
  Impl& impl = *impl_;
  const ServeOptions& o = impl.options;
  const std::shared_ptr<bus::Signal>& signal = stop.signal();
  std::unique_ptr<bus::Reader<protocol::WorldStatus>> statuses;
  std::unique_ptr<bus::Reader<protocol::WorldEvent>> events;
  if (participant != nullptr) {
    statuses = participant->create_reader<protocol::WorldStatus>({"", signal, bus::Durability::kTransientLocal, 64});
    events = participant->create_reader<protocol::WorldEvent>({"", signal, bus::Durability::kVolatile, 256});
    std::lock_guard<std::mutex> lock(impl.model_mutex);
    impl.model =
        LiveModel(fmt::format("DDS domain {} ({})", participant->domain_id(), bus::to_string(participant->vendor())));
    if (o.run_dir.empty()) impl.model.set_map_note("no terrain: start serve with --run-dir (the run's --out folder)");
  }
  impl.publish_state();

  std::thread http_thread([&impl] { impl.http.listen_after_bind(); });
  std::thread follower;
  const std::string dir = o.replay_dir.empty() ? o.run_dir : o.replay_dir;
  if (!dir.empty())
    follower = std::thread([&impl, dir, replay = !o.replay_dir.empty()] {
      try {
        impl.follow(dir, replay);
      } catch (const std::exception& e) {  // nothing escapes the thread: the page says why the terrain stopped
        impl.set_note(fmt::format("stopped following the run folder: {}", e.what()));
      }
    });

  const std::string host =
      o.bind_address.find(':') == std::string::npos ? o.bind_address : fmt::format("[{}]", o.bind_address);
  const std::string source = participant ? fmt::format("following DDS domain {}", participant->domain_id())
                                         : fmt::format("replaying {}", o.replay_dir);
  const std::string terrain = o.run_dir.empty() ? std::string() : fmt::format(", terrain from {}", o.run_dir);
  out << fmt::format("marsala-monitor: live view on http://{}:{}/ ({}{}); Ctrl-C stops", host, o.port, source, terrain)
      << std::endl;

  const auto publish_interval =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(o.publish_interval_s));
  Clock::time_point last_publish = Clock::now();
  WorldGate gate(out);  // only a run's own world speaks for it
  while (!stop.stop_requested()) {
    if (statuses) {
      std::vector<protocol::WorldStatus> batch = gate.statuses(statuses->take_received());
      std::stable_sort(batch.begin(), batch.end(), [](const auto& a, const auto& b) { return a.step < b.step; });
      std::vector<protocol::WorldEvent> event_batch = gate.events(events->take_received());
      if (!batch.empty() || !event_batch.empty()) {
        const Clock::time_point now = Clock::now();
        std::lock_guard<std::mutex> lock(impl.model_mutex);
        for (const protocol::WorldStatus& s : batch) impl.model.on_status(s, now);
        for (const protocol::WorldEvent& e : event_batch) impl.model.on_event(e);
        impl.model_changed = true;
      }
    }
    const Clock::time_point now = Clock::now();
    // Republished at least every second without news, so that the page sees how old the latest status is.
    if ((impl.model_changed && now - last_publish >= publish_interval) || now - last_publish >= 1s) {
      impl.model_changed = false;
      impl.publish_state();
      last_publish = now;
    }
    signal->wait_until(impl.model_changed ? last_publish + publish_interval : now + publish_interval);
  }

  {
    std::lock_guard<std::mutex> lock(impl.stop_mutex);
    impl.stopping = true;
  }
  impl.stop_cv.notify_all();
  if (follower.joinable()) follower.join();
  impl.http.stop();
  http_thread.join();
  out << "marsala-monitor: live view stopped" << std::endl;
  return 0;
}

}  // namespace marsala::monitor
