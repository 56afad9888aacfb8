#pragma once
// Shared by the binding units of the Python package cf (python/): conversions between
// numpy arrays and libcf's types, and the checks that turn bad arguments into cf.Error.

#include <cf/graph.hpp>
#include <cf/params.hpp>
#include <cf/pc.hpp>
#include <cf/polyhedron.hpp>
#include <cf/types.hpp>

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <string>
#include <vector>

namespace cfpy {

namespace py = pybind11;

/// Raises cf.Error (a ValueError) with the message.
[[noreturn]] inline void fail(const std::string& message) { throw cf::Error(message); }

/// float64 and C-contiguous: what libcf reads in place.
using RealArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// `h` (an array or a sequence of numbers) as RealArray: a float64, C-contiguous array is used
/// as it is (no copy); booleans, integers, float32 and strided arrays are converted. Anything
/// else (complex, strings, objects) raises cf.Error naming `what` and its type, prefixed by
/// `where`.
RealArray real_array(const py::handle& h, const char* what, const std::string& where);

/// A pose from a translation (3, mm) and a unit quaternion (4, w x y z), normalised as
/// cfreplay does. `where` prefixes messages ("step", "replay: row 3").
cf::Pose pose_from(const double* p, const double* q, const std::string& where);

/// Params from keyword arguments (names and units of cf::Params' fields), starting from
/// `base`. Unknown names and values out of range raise cf.Error naming the function.
cf::Params params_from_kwargs(const cf::Params& base, const py::kwargs& kwargs,
                              const std::string& where);

/// A PC from "type:a:b", a (type, a, b) tuple or a cf.Pc.
cf::Pc pc_from_py(const py::handle& h);
/// A PC set from "type:a:b;..." or a sequence of PCs.
cf::PcSet pcset_from_py(const py::handle& h);
/// The PCs, which pybind11 gives Python as a list of cf.Pc.
std::vector<cf::Pc> pcs_to_py(const cf::PcSet& pcs);

/// Gives every function and method of `m` a doc that inspect.signature reads (names and
/// defaults), keeping pybind11's typed signature below it (signatures.cpp). Call last.
void add_text_signatures(py::module_& m);

void bind_graph(py::module_& m);
void bind_render(py::module_& m);

}  // namespace cfpy
