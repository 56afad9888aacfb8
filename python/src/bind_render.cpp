// cf.Renderer (one servo tick at a pose) and cf._cf.replay (libcf's replay engine, cf::Replay,
// over numpy arrays of poses).

#include "common.hpp"

#include <cf/file_io.hpp>
#include <cf/model.hpp>
#include <cf/renderer.hpp>
#include <cf/replay.hpp>
#include <cf/servo.hpp>
#include <cf/state.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>

namespace cfpy {

namespace {

using Array = RealArray;

py::array_t<double> vec(const cf::Vec3& v) { return py::array_t<double>(3, v.data()); }

std::string shape_of(const Array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

/// The per-tick record of one renderer result: the C++ result's fields and cfreplay's row.
py::dict step_dict(const cf::HapticResult& r) {
  py::dict d;
  cf::ReplayRow row;
  cf::fill_replay_row(r, row);
  d["t_s"] = r.t_s;
  d["cf"] = r.cf.valid() ? r.cf.value() : -1;
  d["pcs"] = pcs_to_py(r.pcs);
  d["pcs_string"] = row.pcs;
  d["motion"] = row.motion;
  d["status"] = row.status;
  d["identification"] = std::string(r.identification);
  d["num_detected"] = r.num_detected;
  d["F_W"] = vec(r.F_W);
  d["M_W"] = vec(r.M_W);
  d["F_A"] = vec(r.F_A);
  d["M_A"] = vec(r.M_A);
  d["regimes"] = row.regimes;
  d["F_contact_W"] = vec(r.F_contact_W);
  d["M_contact_W"] = vec(r.M_contact_W);
  d["proxy_p"] = vec(r.X_WP.t_BA);
  d["proxy_constrained"] = r.proxy != nullptr && r.proxy->constrained;
  if (r.force != nullptr) {
    const cf::ForceResult& f = *r.force;
    d["F_gravity_W"] = vec(f.F_gravity_W);
    d["reference_W"] = vec(f.reference_W);
    d["centroid_W"] = vec(f.centroid_W);
    d["conservative"] = f.conservative;
    d["dof"] = f.freedoms.dof;
    d["translation_dof"] = f.freedoms.translation_dof;
    d["pure_rotation"] = f.freedoms.pure_rotation;
    py::list pcf;
    for (int k = 0; k < f.num_pcs + f.num_approaching; ++k) {
      const cf::PcForce& p = f.pcs[static_cast<std::size_t>(k)];
      py::dict e;
      e["pc"] = p.pc;
      e["regime"] = std::string(cf::to_string(p.regime));
      e["R_WT"] = cf::Mat3(p.R_WT);
      e["origin_W"] = vec(p.origin_W);
      e["p_W"] = vec(p.p_W);
      e["distance"] = p.distance;
      e["F_cy"] = p.F_cy;
      e["s_mm"] = p.s_mm;
      e["s_bound_mm"] = p.s_bound_mm;
      e["F_T"] = vec(p.F_T);
      e["F_W"] = vec(p.F_W);
      e["gained"] = p.gained;
      pcf.append(e);
    }
    d["pc_forces"] = pcf;
  }
  return d;
}

/// The rows of a replay, kept for to_csv (cfreplay's format, cf::append_csv).
struct ReplayRows {
  std::vector<cf::ReplayRow> rows;
};

/// One renderer bound to its graph (kept alive by the Python object).
struct Renderer {
  Renderer(const cf::CfGraph& g, const cf::Params& p) : r(g, p) {}
  cf::HapticRenderer r;
  bool stepped = false;  ///< since construction or reset
  double last_t = 0;
};

cf::Params params_arg(const py::object& params, const py::kwargs& kw, const std::string& where) {
  cf::Params base;
  if (!params.is_none()) {
    if (!py::isinstance<cf::Params>(params)) fail(where + ": params must be a cf.Params or None");
    base = params.cast<cf::Params>();
  }
  return params_from_kwargs(base, kw, where);
}

/// One tick's arguments checked (time increasing after `last_t` when `stepped`), as a pose.
cf::Pose tick_pose(double t_s, const py::object& p, const py::object& q, bool stepped,
                   double last_t) {
  const Array pa = real_array(p, "p", "step"), qa = real_array(q, "q", "step");
  if (pa.ndim() != 1 || pa.shape(0) != 3) fail("step: p must have shape (3,), got " + shape_of(pa));
  if (qa.ndim() != 1 || qa.shape(0) != 4)
    fail("step: q must have shape (4,) (w, x, y, z), got " + shape_of(qa));
  if (!std::isfinite(t_s)) fail("step: t is not finite");
  if (stepped && !(t_s > last_t)) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "step: time %.9g s does not increase (previous step: %.9g s)",
                  t_s, last_t);
    fail(buf);
  }
  return pose_from(pa.data(), qa.data(), "step");
}

/// Renderer.step: the arguments checked, then one tick.
py::dict renderer_step(Renderer& self, double t_s, const py::object& p, const py::object& q) {
  const cf::Pose pose = tick_pose(t_s, p, q, self.stepped, self.last_t);
  self.stepped = true;
  self.last_t = t_s;
  return step_dict(self.r.step(pose, t_s));
}

/// cf.CfState: one servo thread's state (cf::CfState) and the time of its last tick.
struct State {
  explicit State(const cf::CfModel& m) : s(m), model(&m) {}
  cf::CfState s;
  const cf::CfModel* model;
  bool stepped = false;
  double last_t = 0;
};

/// cf.step(model, state, t, p, q): one tick of cf::step, with the GIL released while it runs,
/// so that threads each holding a state of one model step in parallel.
py::dict model_step(const cf::CfModel& model, State& state, double t_s, const py::object& p,
                    const py::object& q) {
  if (state.model != &model) fail("step: the state was made for another model");
  const cf::Pose pose = tick_pose(t_s, p, q, state.stepped, state.last_t);
  const cf::HapticResult* r = nullptr;
  {
    py::gil_scoped_release release;
    r = &cf::step(model, state.s, pose, t_s);
  }
  state.stepped = true;
  state.last_t = t_s;
  return step_dict(*r);
}

py::dict state_step_many(const cf::CfModel& model, State& state, const py::object& t,
                         const py::object& p, const py::object& q);

void bind_model_state(py::module_& m) {
  py::class_<cf::CfModel>(
      m, "CfModel",
      "Everything the servo loop reads and never writes (cf::CfModel): CfModel(graph, "
      "params=None, **params). One model is shared by every thread; each thread steps its own "
      "CfState with cf.step().")
      .def(py::init([](const cf::CfGraph& g, const py::object& params, const py::kwargs& kw) {
             return std::make_unique<cf::CfModel>(g, params_arg(params, kw, "CfModel"));
           }),
           py::arg("graph"), py::arg("params") = py::none(), py::keep_alive<1, 2>())
      .def_property_readonly("params", [](const cf::CfModel& model) { return model.params(); });
  py::class_<State>(m, "CfState",
                    "One servo thread's state for one CfModel (cf::CfState): CfState(model). "
                    "Not thread-safe: one per thread.")
      .def(py::init<const cf::CfModel&>(), py::arg("model"), py::keep_alive<1, 2>())
      .def(
          "reset",
          [](State& self) {
            self.s.reset();
            self.stepped = false;
          },
          "Forgets the history (previous CF, stick anchors, filters) and the last tick's time.");
  m.def("step", &model_step, py::arg("model"), py::arg("state"), py::arg("t"), py::arg("p"),
        py::arg("q"),
        "One servo tick of `state` on `model` (cf::step), the GIL released while it runs: t "
        "(s, increasing per state), p (3, mm), q (4, unit quaternion w, x, y, z). Returns the "
        "dict Renderer.step returns.");
  m.def("_step_many", &state_step_many, py::arg("model"), py::arg("state"), py::arg("t"),
        py::arg("p"), py::arg("q"), "N ticks of cf.step at once (cf.step_many wraps the result).");
}

py::dict renderer_step_many(Renderer& self, const py::object& t, const py::object& p,
                            const py::object& q);

void bind_renderer(py::module_& m) {
  py::class_<Renderer>(
      m, "Renderer",
      "The haptic renderer (cf::HapticRenderer) of one graph: Renderer(graph, params=None, "
      "**params). step() runs one servo tick: detect, identify the CF, classify the prior "
      "motion, compute the force and moment.")
      .def(py::init([](const cf::CfGraph& g, const py::object& params, const py::kwargs& kw) {
             return std::make_unique<Renderer>(g, params_arg(params, kw, "Renderer"));
           }),
           py::arg("graph"), py::arg("params") = py::none(), py::keep_alive<1, 2>())
      .def("step", &renderer_step, py::arg("t"), py::arg("p"), py::arg("q"),
           "One servo tick at time t (s, increasing), A's translation p (3, mm) and rotation q (4, "
           "unit "
           "quaternion w, x, y, z; x_B = R x_A + p). Returns a dict named like cf::HapticResult's "
           "fields: "
           "t_s, cf (-1 for none), pcs, motion, status, identification, num_detected, F_W, M_W, "
           "F_A, "
           "M_A, and the force model's F_contact_W, F_gravity_W, dof, pc_forces (per PC: regime, "
           "distance, F_cy, task frame R_WT, ...).")
      .def("_step_many", &renderer_step_many, py::arg("t"), py::arg("p"), py::arg("q"),
           "N ticks at once (cf.Renderer.step_many wraps the result).")
      .def(
          "reset",
          [](Renderer& self) {
            self.r.reset();
            self.stepped = false;
          },
          "Forgets the history (previous CF, anchors, filters).")
      .def_property_readonly("params", [](const Renderer& self) { return self.r.params(); });
}

/// replay's poses from its arrays t (N,), p (N, 3), q (N, 4), checked.
std::vector<cf::TrajectorySample> replay_samples(const py::object& t, const py::object& p,
                                                 const py::object& q, const std::string& where) {
  const Array ta = real_array(t, "t", where), pa = real_array(p, "p", where),
              qa = real_array(q, "q", where);
  if (ta.ndim() != 1) fail(where + ": t must have shape (N,), got " + shape_of(ta));
  const py::ssize_t n = ta.shape(0);
  if (n == 0) fail(where + ": no poses (t is empty)");
  if (pa.ndim() != 2 || pa.shape(0) != n || pa.shape(1) != 3)
    fail(where + ": p must have shape (N, 3) with N = len(t) = " + std::to_string(n) + ", got " +
         shape_of(pa));
  if (qa.ndim() != 2 || qa.shape(0) != n || qa.shape(1) != 4)
    fail(where + ": q must have shape (N, 4) (w, x, y, z) with N = len(t) = " + std::to_string(n) +
         ", got " + shape_of(qa));
  std::vector<cf::TrajectorySample> samples(static_cast<std::size_t>(n));
  const double *T = ta.data(), *P = pa.data(), *Q = qa.data();
  py::gil_scoped_release release;  // the arrays are held above; errors are C++ exceptions
  for (py::ssize_t i = 0; i < n; ++i) {
    auto row = [&] { return where + ": row " + std::to_string(i); };
    if (!std::isfinite(T[i])) fail(row() + ": time is not finite");
    if (i > 0 && !(T[i] > T[i - 1])) {
      char buf[160];
      std::snprintf(buf, sizeof buf, ": time %.9g s does not increase (previous row: %.9g s)", T[i],
                    T[i - 1]);
      fail(row() + buf);
    }
    cf::TrajectorySample& s = samples[static_cast<std::size_t>(i)];
    s.t_s = T[i];
    // The row's name is spelled out only for the message of a pose that is refused.
    const double *p_i = P + 3 * i, *q_i = Q + 4 * i;
    const bool ok = std::isfinite(p_i[0]) && std::isfinite(p_i[1]) && std::isfinite(p_i[2]) &&
                    cf::quaternion_problem(q_i[0], q_i[1], q_i[2], q_i[3]).empty();
    s.X_WD = pose_from(p_i, q_i, ok ? where : row());
  }
  return samples;
}

/// What replay reports per tick beyond cfreplay's rows.
struct ReplayExtras {
  explicit ReplayExtras(std::size_t N)
      : num_detected(N),
        identification(N),
        Fc(3 * N, 0.0),
        Mc(3 * N, 0.0),
        Fg(3 * N, 0.0),
        conservative(N, 0),
        dof(N, 6) {}
  std::vector<std::int32_t> num_detected;
  std::vector<std::string> identification;
  std::vector<double> Fc, Mc, Fg;
  std::vector<std::uint8_t> conservative;
  std::vector<std::int32_t> dof;
};

/// Tick i's values beyond its row.
void record_extras(const cf::HapticResult& r, std::size_t i, ReplayExtras& x) {
  x.num_detected[i] = r.num_detected;
  x.identification[i] = r.identification;
  for (int k = 0; k < 3; ++k) {
    x.Fc[3 * i + static_cast<std::size_t>(k)] = r.F_contact_W[k];
    x.Mc[3 * i + static_cast<std::size_t>(k)] = r.M_contact_W[k];
  }
  if (r.force != nullptr) {
    for (int k = 0; k < 3; ++k) x.Fg[3 * i + static_cast<std::size_t>(k)] = r.force->F_gravity_W[k];
    x.conservative[i] = r.force->conservative;
    x.dof[i] = r.force->freedoms.dof;
  }
}

// Ticks run between two looks for Ctrl-C: about 0.1 s at 100,000 ticks a second.
constexpr std::size_t kTicksPerSignalCheck = 8192;

/// Runs tick(i) for i from `done` to n, without the GIL but taking it back every
/// kTicksPerSignalCheck ticks to let a signal's Python handler run (Ctrl-C raises
/// KeyboardInterrupt within a second). False, with the Python error set, when a handler
/// raised; `done` is then the ticks run.
template <class Tick>
bool run_ticks(std::size_t n, std::size_t& done, const Tick& tick) {
  while (done < n) {
    {
      py::gil_scoped_release release;
      for (const std::size_t end = std::min(n, done + kTicksPerSignalCheck); done < end; ++done)
        tick(done);
    }
    if (PyErr_CheckSignals() != 0) return false;
  }
  return true;
}

/// libcf's replay engine over the samples, without the GIL.
/// @throws py::error_already_set (KeyboardInterrupt) on Ctrl-C.
void run_replay(const cf::CfGraph& g, const std::vector<cf::TrajectorySample>& samples,
                const cf::Params& P, ReplayRows& rows, ReplayExtras& x) {
  cf::TrajectorySamples source(samples);
  cf::Replay replay(g, P, source);
  rows.rows.resize(samples.size());
  std::size_t done = 0;
  const bool whole = run_ticks(samples.size(), done, [&](std::size_t i) {
    if (replay.next(rows.rows[i])) record_extras(replay.result(), i, x);
  });
  if (!whole) throw py::error_already_set();
}

/// A column of text (ASCII: PC lists, motion types, statuses, regimes) as a numpy unicode
/// array of its longest item's width, allocated here (with the GIL) and filled by fill()
/// (without it).
class TextColumn {
 public:
  TextColumn(std::size_t n, std::size_t width)
      : width_(std::max<std::size_t>(1, width)),
        a_(py::dtype("<U" + std::to_string(width_)), std::vector<py::ssize_t>{py::ssize_t(n)}) {
    data_ = static_cast<std::uint32_t*>(a_.mutable_data());
  }
  /// Row i's text, as UCS-4 code points padded with zeros. No GIL needed.
  void fill(std::size_t i, const std::string& text) {
    std::uint32_t* out = data_ + i * width_;
    for (std::size_t k = 0; k < width_; ++k) {
      const auto c = k < text.size() ? static_cast<unsigned char>(text[k]) : 0u;
      if (c >= 0x80) fail("replay: internal error: a text column holds a non-ASCII byte");
      out[k] = c;  // libcf writes these columns in ASCII
    }
  }
  const py::array& array() const { return a_; }

 private:
  std::size_t width_;
  py::array a_;
  std::uint32_t* data_;
};

/// The widths of replay's text columns: pcs, motion, status, regimes, identification.
std::array<std::size_t, 5> text_widths(const ReplayRows& rows, const ReplayExtras& x) {
  std::array<std::size_t, 5> w{};
  for (std::size_t i = 0; i < rows.rows.size(); ++i) {
    const cf::ReplayRow& r = rows.rows[i];
    const std::size_t len[5] = {r.pcs.size(), r.motion.size(), r.status.size(), r.regimes.size(),
                                x.identification[i].size()};
    for (int k = 0; k < 5; ++k) w[k] = std::max(w[k], len[k]);
  }
  return w;
}

/// replay's result: per-tick arrays by name, and the rows for to_csv. The arrays are
/// allocated with the GIL and filled without it, so that threads stepping their own states
/// hold it only for the allocations.
py::dict replay_dict(std::unique_ptr<ReplayRows> rows, const ReplayExtras& x) {
  const std::size_t N = rows->rows.size();
  const auto n = static_cast<py::ssize_t>(N);
  std::array<std::size_t, 5> widths{};
  {
    py::gil_scoped_release release;
    widths = text_widths(*rows, x);
  }
  const std::vector<py::ssize_t> shape3{n, 3};
  py::array_t<double> tt(n), FW(shape3), MW(shape3), FA(shape3), MA(shape3), FC(shape3), MC(shape3),
      FG(shape3), PP(shape3), PQ(std::vector<py::ssize_t>{n, 4});
  py::array_t<std::int32_t> cfa(n), nd(n), dofa(n);
  py::array_t<bool> cons(n);
  TextColumn pcs(N, widths[0]), motion(N, widths[1]), status(N, widths[2]), regimes(N, widths[3]),
      ident(N, widths[4]);
  double *t_out = tt.mutable_data(), *fw = FW.mutable_data(), *mw = MW.mutable_data(),
         *fa = FA.mutable_data(), *ma = MA.mutable_data(), *fc = FC.mutable_data(),
         *mc = MC.mutable_data(), *fg = FG.mutable_data(), *pp = PP.mutable_data(),
         *pq = PQ.mutable_data();
  std::int32_t *cf_out = cfa.mutable_data(), *nd_out = nd.mutable_data(),
               *dof_out = dofa.mutable_data();
  bool* cons_out = cons.mutable_data();
  {
    py::gil_scoped_release release;
    for (std::size_t i = 0; i < N; ++i) {
      const cf::ReplayRow& r = rows->rows[i];
      t_out[i] = r.t_s;
      cf_out[i] = r.cf;
      nd_out[i] = x.num_detected[i];
      dof_out[i] = x.dof[i];
      cons_out[i] = x.conservative[i] != 0;
      for (std::size_t k = 0; k < 3; ++k) {
        const std::size_t K = 3 * i + k;
        const auto e = static_cast<Eigen::Index>(k);
        fw[K] = r.F_W[e], mw[K] = r.M_W[e], fa[K] = r.F_A[e], ma[K] = r.M_A[e];
        fc[K] = x.Fc[K], mc[K] = x.Mc[K], fg[K] = x.Fg[K], pp[K] = r.X_WP.t_BA[e];
      }
      Eigen::Quaterniond q_WP(r.X_WP.R_BA);
      if (q_WP.w() < 0) q_WP.coeffs() = -q_WP.coeffs();
      const double wxyz[4] = {q_WP.w(), q_WP.x(), q_WP.y(), q_WP.z()};
      std::copy(wxyz, wxyz + 4, pq + 4 * i);
      pcs.fill(i, r.pcs);
      motion.fill(i, r.motion);
      status.fill(i, r.status);
      regimes.fill(i, r.regimes);
      ident.fill(i, x.identification[i]);
    }
  }
  py::dict d;
  d["t_s"] = tt;
  d["cf"] = cfa;
  d["pcs"] = pcs.array();
  d["motion"] = motion.array();
  d["status"] = status.array();
  d["identification"] = ident.array();
  d["num_detected"] = nd;
  d["F_W"] = FW;
  d["M_W"] = MW;
  d["F_A"] = FA;
  d["M_A"] = MA;
  d["F_contact_W"] = FC;
  d["M_contact_W"] = MC;
  d["proxy_p"] = PP;
  d["proxy_q"] = PQ;
  d["F_gravity_W"] = FG;
  d["conservative"] = cons;
  d["dof"] = dofa;
  d["regimes"] = regimes.array();
  d["_rows"] = py::cast(std::move(rows));
  return d;
}

/// Renderer.step_many: N ticks of this renderer, its state carried on from the ticks before,
/// without the GIL. The renderer is held by this call for its length (a second thread
/// stepping the same Renderer meanwhile is the caller's race, as with any C++ renderer).
/// N ticks of `tick(pose, t)` (a renderer's or a state's), the GIL released while they run;
/// the first time after `last_t` when `stepped`, both updated.
template <class Tick>
py::dict step_many(const py::object& t, const py::object& p, const py::object& q, bool& stepped,
                   double& last_t, const Tick& tick) {
  const std::vector<cf::TrajectorySample> samples = replay_samples(t, p, q, "step_many");
  if (stepped && !(samples.front().t_s > last_t)) {
    char buf[160];
    std::snprintf(buf, sizeof buf,
                  "step_many: time %.9g s does not increase (previous step: %.9g s)",
                  samples.front().t_s, last_t);
    fail(buf);
  }
  auto rows = std::make_unique<ReplayRows>();
  ReplayExtras extras(samples.size());
  rows->rows.resize(samples.size());
  std::size_t done = 0;
  const bool whole = run_ticks(samples.size(), done, [&](std::size_t i) {
    const cf::HapticResult& r = tick(samples[i].X_WD, samples[i].t_s);
    cf::fill_replay_row(r, rows->rows[i]);
    record_extras(r, i, extras);
  });
  // On Ctrl-C the renderer has taken the ticks before it: the next call carries on there.
  if (done > 0) {
    stepped = true;
    last_t = samples[done - 1].t_s;
  }
  if (!whole) throw py::error_already_set();
  return replay_dict(std::move(rows), extras);
}

py::dict renderer_step_many(Renderer& self, const py::object& t, const py::object& p,
                            const py::object& q) {
  return step_many(t, p, q, self.stepped, self.last_t,
                   [&self](const cf::Pose& X, double t_s) -> const cf::HapticResult& {
                     return self.r.step(X, t_s);
                   });
}

py::dict state_step_many(const cf::CfModel& model, State& state, const py::object& t,
                         const py::object& p, const py::object& q) {
  if (state.model != &model) fail("step_many: the state was made for another model");
  return step_many(t, p, q, state.stepped, state.last_t,
                   [&](const cf::Pose& X, double t_s) -> const cf::HapticResult& {
                     return cf::step(model, state.s, X, t_s);
                   });
}

py::dict replay(const cf::CfGraph& g, const py::object& t, const py::object& p, const py::object& q,
                const py::object& params, const py::kwargs& kw) {
  const std::string where = "replay";
  const cf::Params P = params_arg(params, kw, where);
  const std::vector<cf::TrajectorySample> samples = replay_samples(t, p, q, where);
  auto rows = std::make_unique<ReplayRows>();
  ReplayExtras extras(samples.size());
  run_replay(g, samples, P, *rows, extras);
  return replay_dict(std::move(rows), extras);
}

}  // namespace

void bind_render(py::module_& m) {
  bind_renderer(m);
  bind_model_state(m);

  py::class_<ReplayRows>(m, "_ReplayRows")
      .def("__len__", [](const ReplayRows& r) { return r.rows.size(); })
      .def(
          "csv",
          [](const ReplayRows& r) {
            std::string text = cf::replay_csv_header();
            text += '\n';
            for (const cf::ReplayRow& row : r.rows) {
              cf::append_csv(row, text);
              text += '\n';
            }
            return text;
          },
          "The rows as cfreplay writes them (header first).");

  m.def(
      "_read_trajectory",
      [](const std::string& path) {
        std::vector<cf::TrajectorySample> samples;
        {
          py::gil_scoped_release release;
          cf::TrajectoryCsvReader reader = cf::TrajectoryCsvReader::open(path);
          cf::TrajectorySample s;
          while (reader.next(s)) samples.push_back(s);
        }
        const auto n = static_cast<py::ssize_t>(samples.size());
        py::array_t<double> t(n), p({n, py::ssize_t{3}}), q({n, py::ssize_t{4}});
        auto tt = t.mutable_unchecked<1>();
        auto pp = p.mutable_unchecked<2>();
        auto qq = q.mutable_unchecked<2>();
        for (py::ssize_t i = 0; i < n; ++i) {
          const cf::TrajectorySample& s = samples[static_cast<std::size_t>(i)];
          tt(i) = s.t_s;
          for (py::ssize_t k = 0; k < 3; ++k) pp(i, k) = s.X_WD.t_BA[k];
          for (py::ssize_t k = 0; k < 4; ++k) qq(i, k) = s.q[static_cast<std::size_t>(k)];
        }
        return py::make_tuple(t, p, q);
      },
      py::arg("path"),
      "The trajectory reader (cf::TrajectoryCsvReader): (t, p, q) arrays, q as read.");
  m.def(
      "_write_text",
      [](const std::string& path, const std::string& text, const std::vector<std::string>& inputs) {
        py::gil_scoped_release release;
        cf::write_outputs({{path, text}}, inputs, "writing");
      },
      py::arg("path"), py::arg("text"), py::arg("inputs"),
      "Writes a file whole or not at all, never over one of `inputs` (cf::write_outputs).");

  m.def("replay", &replay, py::arg("graph"), py::arg("t"), py::arg("p"), py::arg("q"),
        py::arg("params") = py::none(),
        "The replay engine (cf::Replay) over arrays; the package's cf.replay wraps the result.");
}

}  // namespace cfpy
