// The replay engine and its CSV rows (cf/replay.hpp).

#include <cf/force.hpp>
#include <cf/replay.hpp>

#include "replay/c_numeric.hpp"

#include <Eigen/Geometry>

#include <charconv>
#include <cstdio>

namespace cf {

namespace {

// Appends `text` joined to what `out` holds with ';' between items.
void append_item(std::string& out, const std::string& text) {
  if (!out.empty()) out += ';';
  out += text;
}

}  // namespace

void fill_replay_row(const HapticResult& r, ReplayRow& row) {
  row.t_s = r.t_s;
  row.cf = r.cf.valid() ? r.cf.value() : -1;
  row.pcs.clear();
  row.regimes.clear();
  row.discontinuities.clear();
  if (!r.pcs.empty()) {
    row.pcs = to_string(r.pcs);
  } else if (r.force != nullptr) {
    // No CF fits: list the contacts that were rendered conservatively.
    for (int k = 0; k < r.force->num_pcs; ++k) append_item(row.pcs, to_string(r.force->pcs[k].pc));
  }
  row.motion = to_string(r.motion);
  row.F_W = r.F_W;
  row.M_W = r.M_W;
  row.F_A = r.F_A;
  row.M_A = r.M_A;
  row.status = to_string(r.status);
  row.X_WD = r.X_WD;
  row.X_WP = r.X_WP;
  row.Fc_W = r.F_contact_W;
  row.Mc_W = r.M_contact_W;
  if (r.force == nullptr) return;
  for (int k = 0; k < r.force->num_pcs; ++k)
    append_item(row.regimes, to_string(r.force->pcs[k].regime));
  // Approaching contacts (eq. (1) only) follow, named, as they are not among the pcs.
  for (int k = r.force->num_pcs; k < r.force->num_pcs + r.force->num_approaching; ++k)
    append_item(row.regimes, "approaching:" + to_string(r.force->pcs[k].pc));
  row.discontinuities = discontinuities_string(r.force->discontinuities);
}

const char* replay_csv_header() {
  return "t,cf,pcs,motion,Fx,Fy,Fz,Mx,My,Mz,FAx,FAy,FAz,MAx,MAy,MAz,status,regimes,"
         "proxy_tx,proxy_ty,proxy_tz,proxy_qw,proxy_qx,proxy_qy,proxy_qz,Fcx,Fcy,Fcz,Mcx,Mcy,Mcz,"
         "discontinuities";
}

void append_csv(const ReplayRow& r, std::string& out) {
  const internal::CNumericScope c_numbers;
  // The proxy's attitude as a unit quaternion with qw >= 0 (one of the two that name it).
  Eigen::Quaterniond q(r.X_WP.R_BA);
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  // The time as its shortest round-trip decimal, so that any two distinct times stay distinct
  // (ticks of 1e-7 s too) and a time read from a trajectory is written as it was given.
  char t[32];
  *std::to_chars(t, t + sizeof t - 1, r.t_s).ptr = '\0';
  char buf[1024];
  std::snprintf(buf, sizeof buf, "%s,%d,", t, r.cf);
  out += buf;
  out += r.pcs;
  out += ',';
  out += r.motion;
  std::snprintf(buf, sizeof buf, ",%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,",
                r.F_W.x(), r.F_W.y(), r.F_W.z(), r.M_W.x(), r.M_W.y(), r.M_W.z(), r.F_A.x(),
                r.F_A.y(), r.F_A.z(), r.M_A.x(), r.M_A.y(), r.M_A.z());
  out += buf;
  out += r.status;
  out += ',';
  out += r.regimes;
  std::snprintf(buf, sizeof buf,
                ",%.9g,%.9g,%.9g,%.12f,%.12f,%.12f,%.12f,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,",
                r.X_WP.t_BA.x(), r.X_WP.t_BA.y(), r.X_WP.t_BA.z(), q.w(), q.x(), q.y(), q.z(),
                r.Fc_W.x(), r.Fc_W.y(), r.Fc_W.z(), r.Mc_W.x(), r.Mc_W.y(), r.Mc_W.z());
  out += buf;
  out += r.discontinuities;
}

struct Replay::Impl {
  HapticRenderer renderer;
  TrajectorySource* source;
  TrajectorySample sample;
  const HapticResult* result = nullptr;
  long ticks = 0;

  Impl(const CfGraph& graph, const Params& params, TrajectorySource& s)
      : renderer(graph, params), source(&s) {}
};

Replay::Replay(const CfGraph& graph, const Params& params, TrajectorySource& source)
    : impl_(std::make_unique<Impl>(graph, params, source)) {}
Replay::~Replay() = default;
Replay::Replay(Replay&&) noexcept = default;
Replay& Replay::operator=(Replay&&) noexcept = default;

bool Replay::next(ReplayRow& row) {
  Impl& in = *impl_;
  const double previous_t = in.sample.t_s;
  if (!in.source->next(in.sample)) return false;
  // The renderer's friction and impact laws need time to advance; a source of arrays does
  // not check it itself.
  if (in.ticks > 0 && !(in.sample.t_s > previous_t)) {
    char buf[160];
    const internal::CNumericScope c_numbers;
    std::snprintf(buf, sizeof buf,
                  "sample %ld (t = %.9g s): time does not increase (previous sample: %.9g s)",
                  in.ticks + 1, in.sample.t_s, previous_t);
    throw Error(buf);
  }
  in.result = &in.renderer.step(in.sample.X_WD, in.sample.t_s);
  ++in.ticks;
  fill_replay_row(*in.result, row);
  return true;
}

const HapticResult& Replay::result() const {
  if (impl_->result == nullptr) throw Error("cf::Replay::result: no tick rendered yet");
  return *impl_->result;
}

const TrajectorySample& Replay::sample() const { return impl_->sample; }

long Replay::ticks() const { return impl_->ticks; }

}  // namespace cf
