#pragma once
// Opening an input the way cf::read_input_file does, for readers that take it in pieces
// (a trajectory of millions of rows is never held whole).

#include <cstddef>
#include <string>

namespace cf::internal {

/// Opens `path` for reading without blocking on a FIFO: a descriptor (blocking from then on)
/// of a regular file of at most `max_bytes`, or -1 with `why` set to the reason
/// read_input_file gives. The caller closes it.
int open_input_file(const std::string& path, std::string& why, std::size_t max_bytes);

/// "read failed: <errno's text>".
std::string read_error(int e);

}  // namespace cf::internal
