#pragma once
/// @file
/// Sharded and resumable runs of cfgen (docs/generator.md, "Shards"): `cfgen A B --shard i/K -o PART`
/// searches one slice of the first level-2 round, the bulk of a run, and writes a part file;
/// `cfgen merge PART... -o GRAPH.json` checks the parts, finishes the run and writes the
/// graph, byte for byte the graph of `cfgen A B -o GRAPH.json`.

#include "cfgen/generate.hpp"
#include "cfgen/witness.hpp"

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace cf::tools {

/// What a part file holds.
struct ShardPart {
  std::string path;              ///< where it was read from (for messages)
  GenerateArgs args;             ///< the run's models and options (models as absolute paths)
  std::string a_given, b_given;  ///< the model paths as typed, written into the graph
  std::string fingerprint;       ///< of the models' bytes and every option that shapes the graph
  int index = 0, count = 0;      ///< shard index / count
  std::size_t candidates = 0;    ///< candidates of the first level-2 round, all shards
  std::vector<std::pair<std::size_t, gen::Witness>> results;  ///< by candidate index
};

/// "i/K" with 0 <= i < K <= 4096.
/// @throws cf::Error naming the text and what is wrong.
gen::ShardSpec parse_shard(const std::string& text);

/// A hex digest of the models' bytes and the options that shape the graph (not the thread
/// count, the output path or --quiet).
/// @throws cf::Error when a model cannot be read.
std::string run_fingerprint(const GenerateArgs& args);

/// Writes a part file whole or not at all.
void write_part(const std::string& path, const ShardPart& part);
/// @throws cf::Error "reading shard part '<path>': <problem>".
ShardPart read_part(const std::string& path);

/// The first level-2 round's results, one per candidate, from parts that must come from one
/// run (same fingerprint and shard count) and cover every shard exactly once.
/// @throws cf::Error naming the parts and the problem.
std::vector<gen::Witness> gather_parts(const std::vector<ShardPart>& parts);

/// cfgen --checkpoint DIR: creates DIR and its manifest (checkpoint.json, the run's
/// fingerprint), or reopens it; the store keeps every stage's finished chunks there
/// (stageSSSSS_chunkCCCC.json, each with a digest of its tasks), each written whole.
/// @throws cf::Error when DIR is not a directory or holds another run's checkpoint; the store
/// throws when a kept chunk is damaged or was made for other tasks.
gen::ChunkStore open_checkpoint(const std::string& dir, const std::string& fingerprint,
                               const std::vector<std::string>& inputs);

/// A chunk of tasks, and its results, as text and back (an MPI run sends them between
/// processes this way); doubles round-trip exactly.
/// @throws cf::Error "reading <what>: <problem>" when the text is not such a chunk.
std::string tasks_text(std::size_t chunk, const std::vector<gen::Task>& tasks);
std::vector<gen::Task> tasks_from_text(const std::string& text, const std::string& what, std::size_t& chunk);
std::string task_results_text(std::size_t chunk, const std::vector<gen::TaskResult>& results);
std::vector<gen::TaskResult> task_results_from_text(const std::string& text, const std::string& what,
                                                    std::size_t& chunk);

/// `cfgen merge PART... -o GRAPH.json`: 0 on success.
int run_merge(const std::vector<std::string>& part_paths, const std::string& out_path, int threads,
              bool quiet);

}  // namespace cf::tools
