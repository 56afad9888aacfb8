#pragma once
/// @file
/// cfgen under mpirun (docs/generator.md, "MPI"): `mpirun -n K cfgen A B -o GRAPH.json`.
/// Built only when MPI is found (CF_HAVE_MPI); without mpirun, MPI is never initialised.

#include "cfgen/generate.hpp"

namespace cf::tools {

/// True when this process was started by mpirun or mpiexec (Open MPI, PMIx or PMI set these
/// variables); a plain `cfgen` run never initialises MPI.
bool launched_by_mpi();

/// Every process of the MPI job runs this with the same arguments. Each rank runs the
/// enumeration as one of the job's shards (docs/generator.md, "MPI"): it computes its own
/// chunks of every stage with its threads, sends them to the other ranks and takes theirs
/// as they come, so the graph is byte for byte the one a single-process run writes, and
/// --checkpoint keeps every rank's chunks as shards do. Rank 0 writes the graph and reports
/// progress; the others write nothing. A failing or stopped rank aborts the job.
/// @returns the process exit status.
int run_generate_mpi(GenerateArgs args);

}  // namespace cf::tools
