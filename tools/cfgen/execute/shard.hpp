#pragma once
/// @file
/// Checkpoints, shards and chunks as text (docs/generator.md, "Checkpoints", "Shards"):
/// `cfgen A B -o G.json --checkpoint DIR` keeps every finished chunk in DIR and resumes from
/// it; `--shard i/K` with a DIR that K processes share splits every stage between them.

#include "cfgen/decide/witness.hpp"
#include "cfgen/execute/executor.hpp"
#include "cfgen/generate.hpp"

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace cf::tools {

/// "i/K" with 0 <= i < K <= 4096.
/// @throws cf::Error naming the text and what is wrong.
gen::ShardSpec parse_shard(const std::string& text);

/// A hex digest of the models' bytes and the options that shape the graph (not the thread
/// count, the output path or --quiet).
/// @throws cf::Error when a model cannot be read.
std::string run_fingerprint(const GenerateArgs& args);

/// cfgen --checkpoint DIR: creates DIR and its manifest (checkpoint.json, the run's
/// fingerprint), or reopens it; the store keeps every stage's finished chunks there
/// (stageSSSSS_chunkCCCC.json, each with a digest of its tasks), each written whole.
/// @throws cf::Error when DIR is not a directory or holds another run's checkpoint; the store
/// throws when a kept chunk is damaged or was made for other tasks.
gen::ChunkStore open_checkpoint(const std::string& dir, const std::string& fingerprint,
                                const std::vector<std::string>& inputs);

/// Removes a checkpoint directory that open_checkpoint made: its manifest and chunk files,
/// then the directory if nothing else is in it. Errors are ignored (the graph is written).
void remove_checkpoint(const std::string& dir);

/// The results of chunk `chunk` of stage `stage` as text and back (the ranks of an MPI run
/// send each other their chunks this way); doubles round-trip exactly.
/// @throws cf::Error "reading <what>: <problem>" when the text is not such a chunk.
std::string chunk_text(std::size_t stage, std::size_t chunk,
                       const std::vector<gen::TaskResult>& results);
std::vector<gen::TaskResult> chunk_from_text(const std::string& text, const std::string& what,
                                             std::size_t& stage, std::size_t& chunk);

}  // namespace cf::tools
