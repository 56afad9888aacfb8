// A haptic application's servo loop on the installed libcf: one immutable cf::CfModel, a
// cf::CfState for the servo thread, and a device behind device.hpp's three calls; here a
// simulated hand (simulated_hand.hpp) that comes down onto the L-block's floor, presses
// into it harder than the contact band can hold (the proxy keeps A on the surface), slides
// while pressed and lets go. The servo thread runs at a fixed rate (1 to 10 kHz); the main
// thread prints, once a second, the rate reached, the step time and the wake-up jitter.
// Writes a trace (per tick: time, CF, status, motion, rendered and contact force, device and
// proxy positions, step time, lateness) and the device poses as a cfreplay trajectory, so
// `cfreplay --graph G --trajectory device.csv -o out.csv --plot out.svg` replays and plots it.
//
//   cf_haptic_loop --graph data/graphs/cube_l_block.json [--rate 1000] [--duration 3]
//                  [--trace trace.csv] [--device device.csv] [--check]
//
// --check: exit 1 unless the rate held, every tick with the device below the floor had a CF
// and the proxy stayed on the floor (what the tests run).

#include "servo_loop.hpp"
#include "simulated_hand.hpp"

#include <cf/renderer.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace {

// One tick's record, written by the servo thread into storage reserved before it starts.
struct TickRecord {
  double t_s = 0;
  int cf = -1;
  cf::RenderStatus status = cf::RenderStatus::kNoContact;
  cf::MotionType motion = cf::MotionType::kNone;
  cf::Vec3 F_W = cf::Vec3::Zero(), Fc_W = cf::Vec3::Zero();
  cf::Pose X_WD, X_WP;
  double step_us = 0, late_us = 0;
};

double quantile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(p * static_cast<double>(v.size())))];
}

int usage(const char* why) {
  std::fprintf(
      stderr,
      "cf_haptic_loop: %s\nusage: cf_haptic_loop --graph GRAPH.json [--rate HZ (1000..10000)] "
      "[--duration S] [--scale S] [--max-force N] [--max-torque NMM] [--max-stiffness N/MM] "
      "[--ramp S] [--trace trace.csv] [--device device.csv] [--check]\n",
      why);
  return 2;
}

// The command line.
struct Options {
  std::string graph_path, trace_path = "haptic_loop_trace.csv",
                          device_path = "haptic_loop_device.csv";
  double rate_hz = 1000, duration_s = 3, scale = 1;
  bool check = false;
  // A device that renders this scene unchanged; a 3D Systems Touch is --max-force 3.3
  // --max-stiffness 1 (its torque is not actuated: --max-torque 0, the default here too).
  haptic_loop::DeviceLimits limits{};
  Options() {
    limits.max_force_N = 20;
    limits.max_stiffness_N_per_mm = 2.3;
    limits.ramp_s = 0.2;
  }
};

// Reads the arguments into `o`; 0, or the exit status after the usage message.
int parse(int argc, char** argv, Options& o) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&](const char* name) -> const char* {
      if (i + 1 >= argc) std::exit(usage((std::string(name) + " needs a value").c_str()));
      return argv[++i];
    };
    if (a == "--graph")
      o.graph_path = value("--graph");
    else if (a == "--rate")
      o.rate_hz = std::atof(value("--rate"));
    else if (a == "--duration")
      o.duration_s = std::atof(value("--duration"));
    else if (a == "--trace")
      o.trace_path = value("--trace");
    else if (a == "--device")
      o.device_path = value("--device");
    else if (a == "--scale")
      o.scale = std::atof(value("--scale"));
    else if (a == "--max-force")
      o.limits.max_force_N = std::atof(value("--max-force"));
    else if (a == "--max-torque")
      o.limits.max_torque_Nmm = std::atof(value("--max-torque"));
    else if (a == "--max-stiffness")
      o.limits.max_stiffness_N_per_mm = std::atof(value("--max-stiffness"));
    else if (a == "--ramp")
      o.limits.ramp_s = std::atof(value("--ramp"));
    else if (a == "--check")
      o.check = true;
    else
      return usage(("unknown argument '" + a + "'").c_str());
  }
  const haptic_loop::DeviceLimits& l = o.limits;
  if (o.graph_path.empty()) return usage("--graph is required");
  if (!(o.rate_hz >= 1000 && o.rate_hz <= 10000))
    return usage("--rate must be in [1000, 10000] Hz");
  if (!(o.duration_s > 0 && o.duration_s <= 600)) return usage("--duration must be in (0, 600] s");
  if (!(o.scale > 0 && o.scale <= 1e3)) return usage("--scale must be in (0, 1000]");
  if (!(l.max_force_N > 0 && l.max_force_N <= 1e3))
    return usage("--max-force must be in (0, 1000] N");
  if (!(l.max_torque_Nmm >= 0 && l.max_torque_Nmm <= 1e6))
    return usage("--max-torque must be in [0, 1e6] N mm (0: a force-only device)");
  if (!(l.max_stiffness_N_per_mm > 0 && l.max_stiffness_N_per_mm <= 1e3))
    return usage("--max-stiffness must be in (0, 1000] N/mm");
  if (!(l.ramp_s >= 0 && l.ramp_s <= 10)) return usage("--ramp must be in [0, 10] s");
  return 0;
}

// What the run left: every tick's record, how many ticks ran, and the loop's counts.
struct Run {
  std::vector<TickRecord> records;
  std::size_t ticks = 0;
  haptic_loop::LoopStatus status;
  std::string realtime;  // why real-time priority was refused, or empty
};

// The servo thread steps the model against the simulated hand (read, map, step, guard,
// write, wait: servo_loop.hpp), allocating nothing per tick; the main thread prints the
// statistics once a second.
Run run_loop(const Options& o, const cf::CfModel& model, cf::CfState& state,
             const haptic_loop::Workspace& workspace) {
  // The hand's script (the cube of the bundled L-block graph touches the floor with its
  // centre at y = 35 mm; the hand carries A's 4.9 N, so it sags 4.9 mm below its target).
  // The script is in the scene; the hand moves the device, whose workspace is scaled.
  const double scale = o.scale;
  auto script = [scale](double t) -> cf::Vec3 {
    const double down = std::clamp(t / 0.8, 0.0, 1.0),
                 slide = std::clamp((t - 1.2) / 1.0, 0.0, 1.0),
                 up = std::clamp((t - 2.4) / 0.4, 0.0, 1.0);
    return cf::Vec3(70 - 20 * slide, 45 - 20 * down + 30 * up, 40) /
           scale;  // down to 10 mm below touching
  };
  haptic_loop::SimulatedHand device(o.rate_hz, o.duration_s, script);
  const auto n = static_cast<std::size_t>(std::ceil(o.duration_s * o.rate_hz)) + 1;
  Run run;
  run.records.resize(n);
  std::atomic<std::size_t> done{0};
  std::thread servo([&] {
    run.realtime = haptic_loop::request_realtime();
    run.status = haptic_loop::run_servo(
        device, model, state, o.limits, workspace, 1.0 / o.rate_hz, static_cast<long long>(n),
        [&](long long i, const cf::HapticResult& out, const haptic_loop::DeviceWrench&,
            double late_s, double step_s) {
          TickRecord& r = run.records[static_cast<std::size_t>(i)];
          r.t_s = out.t_s;
          r.cf = out.cf.value();
          r.status = out.status;
          r.motion = out.motion;
          r.F_W = out.F_W;
          r.Fc_W = out.F_contact_W;
          r.X_WD = out.X_WD;
          r.X_WP = out.X_WP;
          r.step_us = 1e6 * step_s;
          r.late_us = 1e6 * late_s;
          done.store(static_cast<std::size_t>(i) + 1, std::memory_order_release);
        });
  });
  std::size_t shown = 0;
  auto report = [&](std::size_t upto, bool full_second) {
    std::vector<double> step, late;
    for (std::size_t k = shown; k < upto; ++k) {
      step.push_back(run.records[k].step_us);
      late.push_back(run.records[k].late_us);
    }
    if (step.empty()) return;
    std::printf(
        "t %5.2f s: %6zu %s%s, step median %.2f us p99 %.2f max %.2f, late median %.1f us p99 "
        "%.1f max %.1f\n",
        run.records[upto - 1].t_s, upto - shown, upto - shown == 1 ? "tick" : "ticks",
        full_second ? " in the last second" : " to the end", quantile(step, 0.5),
        quantile(step, 0.99), quantile(step, 1.0), quantile(late, 0.5), quantile(late, 0.99),
        quantile(late, 1.0));
    shown = upto;
  };
  auto next = std::chrono::steady_clock::now();
  for (;;) {
    next += std::chrono::seconds(1);
    std::this_thread::sleep_until(next);
    const std::size_t upto = done.load(std::memory_order_acquire);
    if (upto == shown) break;
    report(upto, true);
  }
  servo.join();
  report(done.load(), false);
  run.ticks = done.load();
  return run;
}

// What --check looks at: the ticks with the device below the floor, those without a CF,
// and how deep the proxy went.
struct FloorCounts {
  int inside = 0, inside_without_cf = 0;
  double deepest_proxy_mm = 0;
};

// Writes the trace and the device's poses (a cfreplay trajectory); returns the floor counts.
FloorCounts write_files(const Options& o, const Run& run) {
  FILE* f = std::fopen(o.trace_path.c_str(), "w");
  FILE* d = std::fopen(o.device_path.c_str(), "w");
  if (f == nullptr || d == nullptr)
    throw std::runtime_error("cannot write " + (f ? o.device_path : o.trace_path));
  std::fprintf(f,
               "t,cf,status,motion,Fx,Fy,Fz,Fcx,Fcy,Fcz,device_tx,device_ty,device_tz,proxy_tx,"
               "proxy_ty,proxy_tz,"
               "step_us,late_us\n");
  std::fprintf(d, "t,tx,ty,tz,qw,qx,qy,qz\n");
  FloorCounts c;
  for (std::size_t k = 0; k < run.ticks; ++k) {
    const TickRecord& r = run.records[k];
    std::fprintf(
        f, "%.6f,%d,%s,%s,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.3f,%.3f\n",
        r.t_s, r.cf, cf::to_string(r.status), cf::to_string(r.motion), r.F_W.x(), r.F_W.y(),
        r.F_W.z(), r.Fc_W.x(), r.Fc_W.y(), r.Fc_W.z(), r.X_WD.t_BA.x(), r.X_WD.t_BA.y(),
        r.X_WD.t_BA.z(), r.X_WP.t_BA.x(), r.X_WP.t_BA.y(), r.X_WP.t_BA.z(), r.step_us, r.late_us);
    // The device's full pose: its attitude as a unit quaternion (qw >= 0), as cfreplay reads.
    Eigen::Quaterniond q(r.X_WD.R_BA);
    if (q.w() < 0) q.coeffs() = -q.coeffs();
    std::fprintf(d, "%.6f,%.6f,%.6f,%.6f,%.12f,%.12f,%.12f,%.12f\n", r.t_s, r.X_WD.t_BA.x(),
                 r.X_WD.t_BA.y(), r.X_WD.t_BA.z(), q.w(), q.x(), q.y(), q.z());
    if (r.X_WD.t_BA.y() < 35.0) {
      ++c.inside;
      c.inside_without_cf += r.cf < 0 ? 1 : 0;
      c.deepest_proxy_mm = std::max(c.deepest_proxy_mm, 35.0 - r.X_WP.t_BA.y());
    }
  }
  std::fclose(f);
  std::fclose(d);
  return c;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  if (const int status = parse(argc, argv, o); status != 0) return status;
  try {
    // --- What an application does once: the model, shared by every servo thread. ---
    const cf::CfGraph graph = cf::CfGraph::load(o.graph_path);
    // The device's limits and workspace (safety.hpp): the renderer's stiffnesses lowered to
    // what the device renders stably at this scale. Proxy on by default (docs/spec.md, 6b).
    haptic_loop::Workspace workspace;
    workspace.scale = o.scale;
    const cf::CfModel model(graph, haptic_loop::stable_params(cf::Params{}, o.limits, workspace));
    cf::CfState state(model);  // the servo thread's own
    const Run run = run_loop(o, model, state, workspace);
    if (!run.realtime.empty()) std::printf("note: %s\n", run.realtime.c_str());
    std::printf("%lld ticks saturated at the device's limits, %lld zeroed by the watchdog\n",
                run.status.saturated, run.status.zeroed);
    if (run.status.failed) throw std::runtime_error("the servo loop stopped: " + run.status.error);
    const FloorCounts c = write_files(o, run);
    std::printf(
        "%zu %s at %.0f Hz; device below the floor on %d, without a CF on %d; proxy at most "
        "%.4f mm into the floor; trace %s, device poses %s\n",
        run.ticks, run.ticks == 1 ? "tick" : "ticks", o.rate_hz, c.inside, c.inside_without_cf,
        c.deepest_proxy_mm, o.trace_path.c_str(), o.device_path.c_str());
    if (o.check) {
      const bool rate_held = run.ticks + 1 >= static_cast<std::size_t>(o.duration_s * o.rate_hz);
      if (!rate_held || c.inside == 0 || c.inside_without_cf > 0 ||
          c.deepest_proxy_mm > 0.01 + 1e-9) {
        std::fprintf(stderr, "cf_haptic_loop: check failed\n");
        return 1;
      }
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "cf_haptic_loop: %s\n", e.what());
    return 2;
  }
}
