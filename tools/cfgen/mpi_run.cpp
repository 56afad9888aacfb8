#include "cfgen/mpi_run.hpp"

#include "cfgen/shard.hpp"

#include <cf/file_io.hpp>
#include <cf/types.hpp>

#include <mpi.h>

#include <cstdlib>
#include <exception>
#include <iostream>
#include <string>
#include <vector>

namespace cf::tools {
namespace {

enum Tag : int { kRequest = 1, kAssign = 2, kResult = 3 };
constexpr int kShardsPerProcess = 4;  // small shards, so that a slow one holds up little

[[noreturn]] void abort_job(int rank, const std::string& message) {
  std::cerr << "cfgen (MPI rank " << rank << "): " << message << '\n';
  MPI_Abort(MPI_COMM_WORLD, 1);
  std::exit(1);
}

}  // namespace

bool launched_by_mpi() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
    if (std::getenv(v)) return true;
  return false;
}

int run_generate_mpi(GenerateArgs args) {
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  struct Finalize {
    ~Finalize() { MPI_Finalize(); }
  } finalize;
  try {
    if (size == 1) return rank == 0 ? run_generate(args) : 0;
    if (rank == 0) check_output_path(args.out_path, {args.a_path, args.b_path}, "writing graph");
    const int shards = kShardsPerProcess * size;
    GenerateArgs work = args;
    work.shard.count = shards;
    work.quiet = args.quiet || rank != 0;
    int next_free = 0, released = 0;  // rank 0: next shard to hand out, workers told "no more"
    // Rank 0 answers one request (blocking) or every pending one.
    auto serve = [&](bool block) {
      for (;;) {
        MPI_Status st;
        int flag = 1;
        if (block) MPI_Probe(MPI_ANY_SOURCE, kRequest, MPI_COMM_WORLD, &st);
        else MPI_Iprobe(MPI_ANY_SOURCE, kRequest, MPI_COMM_WORLD, &flag, &st);
        if (!flag) return;
        int ignored = 0;
        MPI_Recv(&ignored, 1, MPI_INT, st.MPI_SOURCE, kRequest, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        int id = next_free < shards ? next_free++ : -1;
        if (id < 0) ++released;
        MPI_Send(&id, 1, MPI_INT, st.MPI_SOURCE, kAssign, MPI_COMM_WORLD);
        if (block) return;
      }
    };
    if (rank == 0) {
      work.shard.next = [&] {
        serve(false);
        return next_free < shards ? next_free++ : -1;
      };
    } else {
      work.shard.next = [] {
        int request = 0, id = -1;
        MPI_Send(&request, 1, MPI_INT, 0, kRequest, MPI_COMM_WORLD);
        MPI_Recv(&id, 1, MPI_INT, 0, kAssign, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        return id;
      };
    }
    std::size_t candidates = 0;
    std::vector<std::pair<std::size_t, gen::Witness>> mine;
    work.shard_sink = [&](std::size_t n, const std::vector<std::pair<std::size_t, gen::Witness>>& r) {
      candidates = n;
      mine = r;
    };
    run_generate(work);
    if (rank != 0) {
      const std::string text = results_text(mine);
      MPI_Send(text.data(), static_cast<int>(text.size()), MPI_CHAR, 0, kResult, MPI_COMM_WORLD);
      return 0;
    }
    while (released < size - 1) serve(true);
    std::vector<gen::Witness> all(candidates);
    std::vector<char> have(candidates, 0);
    auto take = [&](const std::vector<std::pair<std::size_t, gen::Witness>>& r) {
      for (const auto& [i, w] : r) {
        all[i] = w;
        have[i] = 1;
      }
    };
    take(mine);
    for (int k = 1; k < size; ++k) {
      MPI_Status st;
      MPI_Probe(MPI_ANY_SOURCE, kResult, MPI_COMM_WORLD, &st);
      int count = 0;
      MPI_Get_count(&st, MPI_CHAR, &count);
      std::string text(static_cast<std::size_t>(count), '\0');
      MPI_Recv(text.data(), count, MPI_CHAR, st.MPI_SOURCE, kResult, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      take(results_from_text(text, "the results of rank " + std::to_string(st.MPI_SOURCE), candidates));
    }
    for (std::size_t i = 0; i < candidates; ++i)
      if (!have[i]) abort_job(rank, "internal error: level-2 candidate " + std::to_string(i) + " was searched by no rank");
    GenerateArgs finish = args;
    finish.first_pairs = &all;
    return run_generate(finish);
  } catch (const Error& e) {
    abort_job(rank, e.what());
  } catch (const std::exception& e) {
    abort_job(rank, std::string("internal error: ") + e.what());
  }
}

}  // namespace cf::tools
