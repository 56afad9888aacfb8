// The C++ reference of the Python tests (libcf/python/tests/test_replay.py): runs cfreplay's
// loop (cf::replay::run over cf::replay::read_trajectory) and prints every tick with 17
// significant digits, where cfreplay's CSV prints 9.
//   cf_python_replay_ref GRAPH POSES.csv > OUT.csv

#include "replay_io.hpp"
#include "replay_run.hpp"

#include <cf/graph.hpp>
#include <cf/params.hpp>

#include <cstdio>
#include <exception>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: cf_python_replay_ref GRAPH POSES.csv\n");
    return 2;
  }
  try {
    const cf::CfGraph graph = cf::CfGraph::load(argv[1]);
    const std::vector<cf::replay::Sample> samples = cf::replay::read_trajectory(argv[2]);
    const std::vector<cf::replay::Row> rows = cf::replay::run(graph, samples, cf::Params());
    std::printf("t,cf,pcs,motion,status,Fx,Fy,Fz,Mx,My,Mz,FAx,FAy,FAz,MAx,MAy,MAz\n");
    for (const cf::replay::Row& r : rows) {
      std::printf("%.17g,%d,%s,%s,%s", r.t, r.cf, r.pcs.c_str(), r.motion.c_str(),
                  r.status.c_str());
      for (const cf::Vec3* v : {&r.F_W, &r.M_W, &r.F_A, &r.M_A})
        for (int k = 0; k < 3; ++k) std::printf(",%.17g", (*v)[k]);
      std::printf("\n");
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "cf_python_replay_ref: %s\n", e.what());
    return 1;
  }
  return 0;
}
