// The C++ reference of the Python tests (python/tests/test_replay.py): runs libcf's
// replay engine (cf::Replay over cf::TrajectoryCsvReader) and prints every tick with 17
// significant digits, where cfreplay's CSV prints 9.
//   cf_python_replay_ref GRAPH POSES.csv > OUT.csv

#include <cf/graph.hpp>
#include <cf/params.hpp>
#include <cf/replay.hpp>

#include <cstdio>
#include <exception>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: cf_python_replay_ref GRAPH POSES.csv\n");
    return 2;
  }
  try {
    const cf::CfGraph graph = cf::CfGraph::load(argv[1]);
    cf::TrajectoryCsvReader poses = cf::TrajectoryCsvReader::open(argv[2]);
    cf::Replay replay(graph, cf::Params(), poses);
    std::printf("t,cf,pcs,motion,status,Fx,Fy,Fz,Mx,My,Mz,FAx,FAy,FAz,MAx,MAy,MAz\n");
    cf::ReplayRow r;
    while (replay.next(r)) {
      std::printf("%.17g,%d,%s,%s,%s", r.t_s, r.cf, r.pcs.c_str(), r.motion.c_str(),
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
