#pragma once
/// @file
/// cfgen under mpirun (docs/generator.md, "MPI"): `mpirun -n K cfgen A B -o GRAPH.json`.
/// Built only when MPI is found (CF_HAVE_MPI); without mpirun, MPI is never initialised.

#include "cfgen/generate.hpp"

namespace cf::tools {

/// True when this process was started by mpirun or mpiexec (Open MPI, PMIx or PMI set these
/// variables); a plain `cfgen` run never initialises MPI.
bool launched_by_mpi();

/// Every process of the MPI job runs this with the same arguments. Rank 0 runs the
/// enumeration: every stage's chunks (levels, motion rounds) go to idle ranks while it
/// computes others, and their results are taken by chunk index, so the graph is byte for
/// byte the one a single-process run writes, and --checkpoint works as in one process. The
/// other ranks read the models, then compute the chunks they are sent with their threads
/// and write nothing. A failing rank aborts the job.
/// @returns the process exit status.
int run_generate_mpi(GenerateArgs args);

}  // namespace cf::tools
