#include "cfgen/execute/mpi_run.hpp"

#include "cfgen/execute/shard.hpp"

#include <cf/file_io.hpp>
#include <cf/types.hpp>

#include <mpi.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <deque>
#include <iostream>
#include <limits>
#include <map>
#include <string>
#include <thread>
#include <vector>

namespace cf::tools {
namespace {

constexpr int kChunk = 5;  // the message tag of a chunk's results

[[noreturn]] void abort_job(int rank, const std::string& message, int status = 1) {
  std::cerr << "cfgen (MPI rank " << rank << "): " << message << '\n';
  MPI_Abort(MPI_COMM_WORLD, status);
  std::exit(status);
}

// The chunks of every stage between the ranks of the job: each rank sends the chunks it
// computes to every other rank and takes theirs as they arrive. Every MPI call is made from
// the thread that runs the stages (MPI_THREAD_FUNNELED).
class MpiShare {
 public:
  MpiShare(int rank, int size) : rank_(rank), size_(size) {}

  gen::ChunkStore store() {
    gen::ChunkStore s;
    s.load = [this](std::size_t stage, std::size_t chunk, const std::vector<gen::Task>& tasks,
                    std::vector<gen::TaskResult>& out) { return take(stage, chunk, tasks, out); };
    s.save = [this](std::size_t stage, std::size_t chunk, const std::vector<gen::Task>&,
                    const std::vector<gen::TaskResult>& results) { send(stage, chunk, results); };
    return s;
  }

  // Returns once every rank has called it: by then every chunk sent has left, and messages
  // that nobody needs (a chunk a rank found in its checkpoint) are received and dropped.
  void finish() {
    MPI_Request barrier = MPI_REQUEST_NULL;
    for (bool entered = false;;) {
      receive();
      arrived_.clear();
      reap();
      if (!entered && sending_.empty()) {
        MPI_Ibarrier(MPI_COMM_WORLD, &barrier);
        entered = true;
      }
      int done = 0;
      if (entered) MPI_Test(&barrier, &done, MPI_STATUS_IGNORE);
      if (done) return;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }

 private:
  struct Sending {
    std::string text;
    std::vector<MPI_Request> requests;
  };

  void send(std::size_t stage, std::size_t chunk, const std::vector<gen::TaskResult>& results) {
    reap();
    sending_.push_back({chunk_text(stage, chunk, results), {}});
    Sending& s = sending_.back();
    for (int r = 0; r < size_; ++r) {
      if (r == rank_) continue;
      s.requests.emplace_back();
      MPI_Isend(s.text.data(), static_cast<int>(s.text.size()), MPI_CHAR, r, kChunk, MPI_COMM_WORLD,
                &s.requests.back());
    }
  }

  // Sends whose every copy has left, from the oldest.
  void reap() {
    while (!sending_.empty()) {
      int done = 0;
      Sending& s = sending_.front();
      MPI_Testall(static_cast<int>(s.requests.size()), s.requests.data(), &done,
                  MPI_STATUSES_IGNORE);
      if (!done) return;
      sending_.pop_front();
    }
  }

  // Every chunk that has come, kept by (stage, chunk) until a stage asks for it.
  void receive() {
    for (;;) {
      MPI_Status st;
      int flag = 0;
      MPI_Iprobe(MPI_ANY_SOURCE, kChunk, MPI_COMM_WORLD, &flag, &st);
      if (!flag) return;
      int count = 0;
      MPI_Get_count(&st, MPI_CHAR, &count);
      std::string text(static_cast<std::size_t>(count), '\0');
      MPI_Recv(text.data(), count, MPI_CHAR, st.MPI_SOURCE, kChunk, MPI_COMM_WORLD,
               MPI_STATUS_IGNORE);
      std::size_t stage = 0, chunk = 0;
      std::vector<gen::TaskResult> r =
          chunk_from_text(text, "a chunk from rank " + std::to_string(st.MPI_SOURCE), stage, chunk);
      arrived_[{stage, chunk}] = std::move(r);
    }
  }

  bool take(std::size_t stage, std::size_t chunk, const std::vector<gen::Task>& tasks,
            std::vector<gen::TaskResult>& out) {
    reap();
    receive();
    const auto it = arrived_.find({stage, chunk});
    if (it == arrived_.end()) return false;
    if (it->second.size() != tasks.size())
      throw Error("stage " + std::to_string(stage) + ", chunk " + std::to_string(chunk) + ": " +
                  std::to_string(it->second.size()) + " results from another rank for " +
                  std::to_string(tasks.size()) + " tasks");
    out = std::move(it->second);
    arrived_.erase(it);
    return true;
  }

  int rank_, size_;
  std::map<std::pair<std::size_t, std::size_t>, std::vector<gen::TaskResult>> arrived_;
  std::deque<Sending> sending_;
};

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
    // Every rank runs the enumeration as shard `rank` of `size`: its own chunks of every stage
    // computed here and sent to the others, theirs taken as they come; rank 0 writes the graph.
    // A rank does not leave the job before it ends, so none is waited for with a patience.
    MpiShare share(rank, size);
    args.shard.index = rank;
    args.shard.count = size;
    args.shard_patience = std::numeric_limits<double>::infinity();
    args.share = share.store();
    if (rank != 0) args.quiet = true;
    const int status = run_generate(args);
    // A rank stopped by a signal ends the job: the others would wait for its chunks.
    if (status != 0) abort_job(rank, "stopped (status " + std::to_string(status) + ")", status);
    share.finish();
    return status;
  } catch (const Error& e) {
    abort_job(rank, e.what());
  } catch (const std::exception& e) {
    abort_job(rank, std::string("internal error: ") + e.what());
  }
}

}  // namespace cf::tools
