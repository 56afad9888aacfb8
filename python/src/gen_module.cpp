// The extension module cf.gen._gen: the model loader (tools/mesh) and cfgen's generator
// (run_generate), built when the CGAL tools are. It links the tools; cf._cf, whose types
// (cf.Polyhedron, cf.CfGraph) and errors it returns and raises, links libcf alone.

#include "common.hpp"

#include "cfgen/execute/stop.hpp"
#include "cfgen/generate.hpp"
#include "mesh/model_loader.hpp"

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <exception>
#include <mutex>
#include <thread>

namespace cfpy {

namespace {

void check_units(const std::string& units, const char* name, const std::string& where) {
  if (cf::tools::mm_per_unit(units) == 0)
    fail(where + ": " + name + " must be 'mm', 'cm', 'm' or 'in', got '" + units + "'");
}

void check_range(double v, double lo, double hi, const char* name, const std::string& where) {
  if (!std::isfinite(v) || v < lo || v > hi) {
    char buf[160];
    std::snprintf(buf, sizeof buf, ": %s must be a finite number in [%g, %g], got %.17g", name, lo,
                  hi, v);
    fail(where + buf);
  }
}

void check_int(int v, int lo, int hi, const char* name, const std::string& where) {
  if (v < lo || v > hi)
    fail(where + ": " + name + " must be an integer in [" + std::to_string(lo) + ", " +
         std::to_string(hi) + "], got " + std::to_string(v));
}

// LoadOptions with the options that decide which facets merge into one face, each checked
// against the ranges cfgen's --coplanar-tol and --crease-angle accept.
cf::tools::LoadOptions merge_options(double coplanar_rel_tol, double crease_angle_deg,
                                     const std::string& where) {
  check_range(coplanar_rel_tol, cf::tools::kMinCoplanarTol, cf::tools::kMaxCoplanarTol,
              "coplanar_rel_tol", where);
  check_range(crease_angle_deg, cf::tools::kMinCreaseAngle, cf::tools::kMaxCreaseAngle,
              "crease_angle_deg", where);
  cf::tools::LoadOptions o;
  o.coplanar_rel_tol = coplanar_rel_tol;
  o.crease_angle_deg = crease_angle_deg;
  return o;
}

// run_generate on a thread of its own while this one, the caller's, checks Python's signals:
// Ctrl-C (KeyboardInterrupt) sets the run's stop flag, the run stops between tasks (keeping
// its finished chunks when it keeps a checkpoint), and the KeyboardInterrupt is raised here.
int generate_stoppable(cf::tools::GenerateArgs& g) {
  cf::gen::StopFlag stop{false};
  g.stop = &stop;
  std::mutex m;
  std::condition_variable cv;
  bool done = false;
  int status = 0;
  std::exception_ptr error;
  std::thread worker([&] {
    try {
      status = cf::tools::run_generate(g);
    } catch (...) {
      error = std::current_exception();
    }
    std::lock_guard<std::mutex> lock(m);
    done = true;
    cv.notify_one();
  });
  for (bool finished = false; !finished;) {
    {
      py::gil_scoped_release release;
      std::unique_lock<std::mutex> lock(m);
      finished = cv.wait_for(lock, std::chrono::milliseconds(100), [&] { return done; });
    }
    if (!finished && PyErr_CheckSignals() != 0) {
      stop = true;
      {
        py::gil_scoped_release release;
        worker.join();
      }
      throw py::error_already_set();
    }
  }
  worker.join();
  if (error) std::rethrow_exception(error);
  return status;
}

// cfgen's run (run_generate) from the binding's arguments, checked as the command line checks
// its options; the graph handed over in memory, and written to out_path unless it is empty.
cf::CfGraph generate(const std::string& a_path, const std::string& b_path,
                     const std::string& out_path, int threads, bool quiet, int max_pcs,
                     double touch_tol, double min_clearance, double good_clearance,
                     double min_margin, double angle_margin, int theta_samples, int max_rotations,
                     const std::string& units, const std::string& units_a,
                     const std::string& units_b, double coplanar_rel_tol, double crease_angle_deg,
                     bool symmetry, bool thorough, const std::string& checkpoint,
                     const std::string& certificates, long long cube_cells, double resolution) {
  const std::string where = "generate";
  // The ranges cfgen's options accept.
  check_int(threads, 0, 1024, "threads", where);
  check_int(max_pcs, 1, 3, "max_pcs", where);
  check_range(touch_tol, 1e-15, 1e-5, "touch_tol", where);
  check_range(min_clearance, 1e-9, 0.1, "min_clearance", where);
  check_range(good_clearance, 1e-9, 1.0, "good_clearance", where);
  check_range(min_margin, 1e-9, 0.1, "min_margin", where);
  check_range(angle_margin, 1e-9, 0.5, "angle_margin", where);
  check_int(theta_samples, 1, 1000, "theta_samples", where);
  check_int(max_rotations, 1, 10000, "max_rotations", where);
  if (cube_cells < 0 || cube_cells > 10000000)
    fail(where + ": cube_cells " + std::to_string(cube_cells) + " is not in [0, 10000000]");
  check_range(resolution, 1e-9, 0.1, "resolution", where);
  const cf::tools::LoadOptions merge = merge_options(coplanar_rel_tol, crease_angle_deg, where);
  check_units(units, "units", where);
  cf::tools::GenerateArgs g;
  g.a_path = a_path;
  g.b_path = b_path;
  g.out_path = out_path;
  g.threads = threads;
  g.quiet = quiet;
  g.max_pcs = max_pcs;
  g.symmetry = symmetry;
  if (thorough && !symmetry) fail(where + ": symmetry=False excludes thorough=True");
  g.thorough = thorough;
  g.cube_cells = static_cast<std::size_t>(cube_cells);
  g.resolution = resolution;
  g.rel.touch_tol = touch_tol;
  g.rel.min_clearance = min_clearance;
  g.rel.good_clearance = good_clearance;
  g.rel.min_margin = min_margin;
  if (const std::string why = cf::tools::conflicting_lengths(g.rel, true); !why.empty())
    fail(where + ": " + why);
  g.search.angle_margin = angle_margin;
  g.search.theta_samples = theta_samples;
  g.search.max_rotations = max_rotations;
  g.load_a.units = units_a.empty() ? units : units_a;
  g.load_b.units = units_b.empty() ? units : units_b;
  check_units(g.load_a.units, "units_a", where);
  check_units(g.load_b.units, "units_b", where);
  g.load_a.coplanar_rel_tol = g.load_b.coplanar_rel_tol = merge.coplanar_rel_tol;
  g.load_a.crease_angle_deg = g.load_b.crease_angle_deg = merge.crease_angle_deg;
  g.checkpoint_dir = checkpoint;
  g.certificates_path = certificates;
  // A checkpoint only when asked for (cfgen keeps one by default for long runs).
  g.no_checkpoint = checkpoint.empty();
  cf::CfGraph graph;
  g.graph_out = &graph;
  const int status = generate_stoppable(g);
  if (status != 0) fail(where + ": cfgen's generator failed with status " + std::to_string(status));
  return graph;
}

}  // namespace

}  // namespace cfpy

PYBIND11_MODULE(_gen, m) {
  using namespace cfpy;
  // cf._cf registers the types this module returns and the errors it raises.
  py::module_::import("cf._cf");
  m.def(
      "load_model",
      [](const std::string& path, const std::string& units, double coplanar_rel_tol,
         double crease_angle_deg, bool check_self_intersection, const std::string& name) {
        check_units(units, "units", "load_model");
        cf::tools::LoadOptions o = merge_options(coplanar_rel_tol, crease_angle_deg, "load_model");
        o.units = units;
        o.check_self_intersection = check_self_intersection;
        o.name = name;
        py::gil_scoped_release release;
        return cf::tools::load_model(path, o);
      },
      py::arg("path"), py::arg("units") = "mm",
      py::arg("coplanar_rel_tol") = cf::tools::LoadOptions{}.coplanar_rel_tol,
      py::arg("crease_angle_deg") = cf::tools::LoadOptions{}.crease_angle_deg,
      py::arg("check_self_intersection") = true, py::arg("name") = "",
      "Reads a closed, outward-oriented polyhedral model (OFF, OBJ, STL or PLY), validates it and "
      "extracts its features (cf::tools::load_model, as cfgen --features). units: the file's "
      "length unit ('mm', 'cm', 'm', 'in'); the model is in mm. coplanar_rel_tol and "
      "crease_angle_deg (degrees): which facets merge into one face, as cfgen's --coplanar-tol "
      "and --crease-angle. Raises cf.Error naming the file and the problem.");

  m.def("generate", &generate, py::arg("a_path"), py::arg("b_path"), py::arg("output"),
        py::arg("threads") = 0, py::arg("quiet") = true, py::arg("max_pcs") = 3,
        py::arg("touch_tol") = cf::tools::RelativeLengths{}.touch_tol,
        py::arg("min_clearance") = cf::tools::RelativeLengths{}.min_clearance,
        py::arg("good_clearance") = cf::tools::RelativeLengths{}.good_clearance,
        py::arg("min_margin") = cf::tools::RelativeLengths{}.min_margin,
        py::arg("angle_margin") = cf::gen::SearchParams{}.angle_margin,
        py::arg("theta_samples") = cf::gen::SearchParams{}.theta_samples,
        py::arg("max_rotations") = cf::gen::SearchParams{}.max_rotations, py::arg("units") = "mm",
        py::arg("units_a") = "", py::arg("units_b") = "",
        py::arg("coplanar_rel_tol") = cf::tools::LoadOptions{}.coplanar_rel_tol,
        py::arg("crease_angle_deg") = cf::tools::LoadOptions{}.crease_angle_deg,
        py::arg("symmetry") = true, py::arg("thorough") = false, py::arg("checkpoint") = "",
        py::arg("certificates") = "", py::arg("cube_cells") = 0,
        py::arg("resolution") = cf::gen::kResolution,
        "cfgen's generation (cf::tools::run_generate): the graph, also written to `output` "
        "unless it is empty; cf.gen.generate wraps it.");
  add_text_signatures(m);
}
