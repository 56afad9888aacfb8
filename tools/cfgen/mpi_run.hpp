#pragma once
/// @file
/// cfgen under mpirun (docs/generator.md, "MPI"): `mpirun -n K cfgen A B -o GRAPH.json`.
/// Built only when MPI is found (CF_HAVE_MPI); without mpirun, MPI is never initialised.

#include "cfgen/generate.hpp"

namespace cf::tools {

/// True when this process was started by mpirun or mpiexec (Open MPI, PMIx or PMI set these
/// variables); a plain `cfgen` run never initialises MPI.
bool launched_by_mpi();

/// Every process of the MPI job runs this with the same arguments: rank 0 hands out shards
/// of the first level-2 round on request (and searches some itself), gathers the results,
/// finishes the run with its threads and writes the graph, byte for byte the one a
/// single-process run writes. Other ranks write nothing. A failing rank aborts the job.
/// @returns the process exit status.
int run_generate_mpi(GenerateArgs args);

}  // namespace cf::tools
