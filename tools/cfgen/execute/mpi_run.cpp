#include "cfgen/execute/mpi_run.hpp"

#include "cfgen/execute/shard.hpp"

#include <cf/file_io.hpp>
#include <cf/types.hpp>

#include <mpi.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <deque>
#include <exception>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

namespace cf::tools {
namespace {

enum Tag : int { kAssign = 2, kResult = 3, kStop = 4 };

[[noreturn]] void abort_job(int rank, const std::string& message) {
  std::cerr << "cfgen (MPI rank " << rank << "): " << message << '\n';
  MPI_Abort(MPI_COMM_WORLD, 1);
  std::exit(1);
}

void send_text(const std::string& text, int to, int tag) {
  MPI_Send(text.data(), static_cast<int>(text.size()), MPI_CHAR, to, tag, MPI_COMM_WORLD);
}

// The message `st` announced, as text.
std::string receive_text(const MPI_Status& st) {
  int count = 0;
  MPI_Get_count(&st, MPI_CHAR, &count);
  std::string text(static_cast<std::size_t>(count), '\0');
  MPI_Recv(text.data(), count, MPI_CHAR, st.MPI_SOURCE, st.MPI_TAG, MPI_COMM_WORLD,
           MPI_STATUS_IGNORE);
  return text;
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
    if (rank != 0) {
      // A worker: chunks of tasks in, their results out, until rank 0 says stop.
      args.quiet = true;
      args.serve = [](const gen::WitnessSearch& search, int threads) {
        for (;;) {
          MPI_Status st;
          MPI_Probe(0, MPI_ANY_TAG, MPI_COMM_WORLD, &st);
          const std::string text = receive_text(st);
          if (st.MPI_TAG == kStop) return 0;
          std::size_t chunk = 0;
          const std::vector<gen::Task> tasks = tasks_from_text(text, "a chunk from rank 0", chunk);
          send_text(task_results_text(
                        chunk, gen::decide_all(
                                   [&search](const gen::Task& t) { return gen::decide(search, t); },
                                   tasks, threads)),
                    0, kResult);
        }
      };
      return run_generate(args);
    }
    // Rank 0 runs the enumeration; each stage's chunks go to idle workers while it computes
    // others itself, and the results are taken by chunk index, so the graph is the one a
    // single process writes.
    // Two chunks in flight per worker: one to compute while rank 0, busy with a chunk of its
    // own, cannot answer; a worker answers in order, so its second chunk starts at once.
    constexpr int kInFlight = 2;
    std::vector<int> idle;  // one entry per free slot
    for (int k = 0; k < kInFlight; ++k)
      for (int r = 1; r < size; ++r) idle.push_back(r);
    args.distribute =
        [&](const std::vector<std::vector<gen::Task>>& chunks, const std::vector<std::size_t>& todo,
            const std::function<std::vector<gen::TaskResult>(std::size_t)>& compute,
            const std::function<void(std::size_t, std::vector<gen::TaskResult> &&)>& done) {
          std::deque<std::size_t> queue(todo.begin(), todo.end());
          int outstanding = 0;
          auto receive = [&] {
            for (;;) {
              MPI_Status st;
              int flag = 0;
              MPI_Iprobe(MPI_ANY_SOURCE, kResult, MPI_COMM_WORLD, &flag, &st);
              if (!flag) return;
              const std::string text = receive_text(st);
              std::size_t chunk = 0;
              std::vector<gen::TaskResult> r = task_results_from_text(
                  text, "the results of rank " + std::to_string(st.MPI_SOURCE), chunk);
              if (chunk >= chunks.size())
                throw Error("rank " + std::to_string(st.MPI_SOURCE) + " answered for chunk " +
                            std::to_string(chunk) + ", which this stage does not have");
              done(chunk, std::move(r));
              idle.push_back(st.MPI_SOURCE);
              --outstanding;
            }
          };
          // Chunks go out without blocking: a worker may be sending a result (which waits for rank
          // 0 to take it) when its next chunk is sent.
          std::deque<std::pair<MPI_Request, std::string>> sending;
          auto hand_out = [&] {
            while (!sending.empty()) {
              int complete = 0;
              MPI_Test(&sending.front().first, &complete, MPI_STATUS_IGNORE);
              if (!complete) break;
              sending.pop_front();
            }
            while (!idle.empty() && !queue.empty()) {
              sending.emplace_back(MPI_REQUEST_NULL,
                                   tasks_text(queue.front(), chunks[queue.front()]));
              std::string& text = sending.back().second;
              MPI_Isend(text.data(), static_cast<int>(text.size()), MPI_CHAR, idle.back(), kAssign,
                        MPI_COMM_WORLD, &sending.back().first);
              queue.pop_front();
              idle.pop_back();
              ++outstanding;
            }
          };
          // Rank 0 computes chunks from the back of the queue on a thread of its own, while this
          // thread (the only one that calls MPI) keeps the workers fed.
          std::thread local;
          std::atomic<bool> local_done{false};
          std::size_t local_chunk = 0;
          std::vector<gen::TaskResult> local_result;
          std::exception_ptr local_error;
          // An error on this thread waits for the chunk in hand (declared last: it must go first,
          // while what the computing thread writes to still exists), then propagates.
          struct JoinOnExit {
            std::thread& t;
            ~JoinOnExit() {
              if (t.joinable()) t.join();
            }
          } join_on_exit{local};
          for (;;) {
            receive();
            hand_out();
            if (local.joinable() && local_done) {
              local.join();
              if (local_error) std::rethrow_exception(local_error);
              done(local_chunk, std::move(local_result));
            }
            if (!local.joinable() && !queue.empty()) {
              local_chunk = queue.back();
              queue.pop_back();
              local_done = false;
              local = std::thread([&] {
                try {
                  local_result = compute(local_chunk);
                } catch (...) {
                  local_error = std::current_exception();
                }
                local_done = true;
              });
            }
            if (queue.empty() && outstanding == 0 && !local.joinable()) break;
            std::this_thread::sleep_for(std::chrono::microseconds(500));
          }
          for (auto& [request, text] : sending) MPI_Wait(&request, MPI_STATUS_IGNORE);
        };
    const int status = run_generate(args);
    for (int r = 1; r < size; ++r) send_text(std::string(), r, kStop);
    return status;
  } catch (const Error& e) {
    abort_job(rank, e.what());
  } catch (const std::exception& e) {
    abort_job(rank, std::string("internal error: ") + e.what());
  }
}

}  // namespace cf::tools
