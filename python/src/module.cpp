// The extension module cf._cf: errors, PCs, parameters. The graph and models are bound in
// bind_graph.cpp, the renderer and the replay in bind_render.cpp. It links libcf alone: the
// model loader and the generator are the module cf.gen._gen (gen_module.cpp).
// docs/python.md describes the Python API.

#include "common.hpp"

#include <cf/version.hpp>

#include <cf/file_io.hpp>  // quaternion_problem: the tools' check of a quaternion

#include <cmath>
#include <cstdio>
#include <functional>
#include <vector>

namespace cfpy {

RealArray real_array(const py::handle& h, const char* what, const std::string& where) {
  // numpy's own reading first (a list becomes an array of the type its items have), so that
  // the kind can be checked before any cast: a cast to float64 would drop a complex number's
  // imaginary part and parse strings.
  py::array in;
  try {
    in = py::array::ensure(h);
  } catch (const py::error_already_set&) {
  }
  if (!in)
    fail(where + ": " + what + " must be an array of numbers, got " + std::string(py::repr(h)));
  const char kind = in.dtype().kind();
  if (kind != 'b' && kind != 'i' && kind != 'u' && kind != 'f')
    fail(where + ": " + what + " must be real numbers, got an array of " +
         std::string(py::str(in.dtype())));
  RealArray a = RealArray::ensure(in);
  if (!a) throw py::error_already_set();
  return a;
}

cf::Pose pose_from(const double* p, const double* q, const std::string& where) {
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(p[i])) fail(where + ": the translation is not finite");
  // The check and message every tool applies to a quaternion it reads (cf/file_io.hpp).
  if (const std::string why = cf::quaternion_problem(q[0], q[1], q[2], q[3]); !why.empty())
    fail(where + ": " + why);
  // As cfreplay reads a row: normalised, then the rotation matrix.
  Eigen::Quaterniond quat(q[0], q[1], q[2], q[3]);
  quat.normalize();
  cf::Pose pose;
  pose.R_BA = quat.toRotationMatrix();
  pose.t_BA = cf::Vec3(p[0], p[1], p[2]);
  return pose;
}

namespace {

// The real-valued parameters: names, ranges and help from libcf's table (cf::param_specs),
// under their Python keywords (flat: every keyword is unique).
using DoubleField = cf::ParamSpec;
const std::vector<cf::ParamSpec>& double_fields() { return cf::param_specs(); }

template <class E>
struct EnumField {
  const char* name;
  std::vector<std::pair<const char*, E>> values;
};

// The choices' names are libcf's (cf::to_string), the ones cfreplay's options take.
template <class E, std::size_t N>
EnumField<E> enum_field(const char* name, const E (&all)[N]) {
  EnumField<E> f{name, {}};
  for (E e : all) f.values.emplace_back(cf::to_string(e), e);
  return f;
}
const EnumField<cf::FrictionDisplacement> kFriction =
    enum_field("friction_displacement", cf::kFrictionDisplacements);
const EnumField<cf::CentroidChoice> kCentroid = enum_field("centroid", cf::kCentroidChoices);
const EnumField<cf::MomentReference> kMomentRef =
    enum_field("moment_reference", cf::kMomentReferences);

template <class E>
std::string enum_name(const EnumField<E>& f, E v) {
  for (const auto& [n, e] : f.values)
    if (e == v) return n;
  return "?";
}

template <class E>
E enum_value(const EnumField<E>& f, const py::handle& h, const std::string& where) {
  std::string allowed;
  for (const auto& [n, e] : f.values)
    allowed += std::string(allowed.empty() ? "" : ", ") + "'" + n + "'";
  if (!py::isinstance<py::str>(h))
    fail(where + ": " + f.name + " must be one of " + allowed + ", got " +
         std::string(py::repr(h)));
  const std::string s = h.cast<std::string>();
  for (const auto& [n, e] : f.values)
    if (s == n) return e;
  fail(where + ": " + f.name + " must be one of " + allowed + ", got '" + s + "'");
}

double double_value(const DoubleField& f, const py::handle& h, const std::string& where) {
  double v;
  try {
    if (py::isinstance<py::bool_>(h) || py::isinstance<py::str>(h)) throw py::cast_error();
    v = py::float_(py::reinterpret_borrow<py::object>(h)).cast<double>();
  } catch (const py::error_already_set&) {
    fail(where + ": " + f.python + " must be a number, got " + std::string(py::repr(h)));
  } catch (const py::cast_error&) {
    fail(where + ": " + f.python + " must be a number, got " + std::string(py::repr(h)));
  }
  if (!f.problem(v).empty()) {
    char buf[120];
    std::snprintf(buf, sizeof buf, " must be a finite number in %s%g, %g], got %.17g",
                  f.lo_open ? "(" : "[", f.lo, f.hi, v);
    fail(where + ": " + f.python + buf);
  }
  return v;
}

cf::Vec3 vec3_value(const char* name, const py::handle& h, const std::string& where) {
  const RealArray a = real_array(h, name, where);
  if (a.ndim() != 1 || a.shape(0) != 3)
    fail(where + ": " + name + " must be 3 numbers (x, y, z), got " + std::string(py::repr(h)));
  const cf::Vec3 v(a.at(0), a.at(1), a.at(2));
  if (!v.allFinite()) fail(where + ": " + std::string(name) + " must be finite");
  return v;
}

void set_param(cf::Params& P, const std::string& key, const py::handle& value,
               const std::string& where) {
  for (const DoubleField& f : double_fields()) {
    if (f.deprecated_python != nullptr && key == f.deprecated_python) {
      // Renamed (two parameters had one name); the old keyword works for one release.
      const std::string msg = where + ": parameter '" + key + "' is now '" + f.python +
                              "'; the old name will be removed in the next release";
      if (PyErr_WarnEx(PyExc_DeprecationWarning, msg.c_str(), 2) != 0)
        throw py::error_already_set();
      f.field(P) = double_value(f, value, where);
      return;
    }
    if (key == f.python) {
      f.field(P) = double_value(f, value, where);
      return;
    }
  }
  if (key == kFriction.name) {
    P.friction_displacement = enum_value(kFriction, value, where);
  } else if (key == kCentroid.name) {
    P.centroid = enum_value(kCentroid, value, where);
  } else if (key == kMomentRef.name) {
    P.moment_reference = enum_value(kMomentRef, value, where);
  } else if (key == "moment_point_A") {
    P.moment_point_A = vec3_value("moment_point_A", value, where);
  } else if (key == "proxy_grip_point_A") {
    P.proxy.grip_point_A = vec3_value("proxy_grip_point_A", value, where);
  } else if (key == "render_approaching" || key == "use_bvh" || key == "proxy" ||
             key == "proxy_friction") {
    if (!py::isinstance<py::bool_>(value))
      fail(where + ": " + key + " must be True or False, got " + std::string(py::repr(value)));
    bool& field = key == "use_bvh"          ? P.detection.use_bvh
                  : key == "proxy"          ? P.proxy.enabled
                  : key == "proxy_friction" ? P.proxy.friction
                                            : P.render_approaching;
    field = value.cast<bool>();
  } else if (key == "max_combinations") {
    if (!py::isinstance<py::int_>(value) || py::isinstance<py::bool_>(value) ||
        value.cast<long long>() < 1 || value.cast<long long>() > 1000000000)
      fail(where + ": max_combinations must be an integer in [1, 1000000000], got " +
           std::string(py::repr(value)));
    P.identification.max_combinations = value.cast<int>();
  } else {
    std::string names;
    for (const DoubleField& f : double_fields())
      names += std::string(names.empty() ? "" : ", ") + f.python;
    names +=
        std::string(", ") + kFriction.name + ", " + kCentroid.name + ", " + kMomentRef.name +
        ", moment_point_A, render_approaching, use_bvh, max_combinations, proxy, proxy_friction, "
        "proxy_grip_point_A";
    fail(where + ": unknown parameter '" + key + "' (parameters: " + names + ")");
  }
}

py::dict params_to_dict(const cf::Params& P) {
  py::dict d;
  for (const DoubleField& f : double_fields()) d[f.python] = f.get(P);
  d[kFriction.name] = enum_name(kFriction, P.friction_displacement);
  d[kCentroid.name] = enum_name(kCentroid, P.centroid);
  d[kMomentRef.name] = enum_name(kMomentRef, P.moment_reference);
  d["moment_point_A"] = py::array_t<double>(3, P.moment_point_A.data());
  d["render_approaching"] = P.render_approaching;
  d["use_bvh"] = P.detection.use_bvh;
  d["max_combinations"] = P.identification.max_combinations;
  d["proxy"] = P.proxy.enabled;
  d["proxy_friction"] = P.proxy.friction;
  d["proxy_grip_point_A"] = py::array_t<double>(3, P.proxy.grip_point_A.data());
  return d;
}

}  // namespace

cf::Params params_from_kwargs(const cf::Params& base, const py::kwargs& kwargs,
                              const std::string& where) {
  cf::Params P = base;
  for (const auto& [k, v] : kwargs) set_param(P, k.cast<std::string>(), v, where);
  return P;
}

cf::Pc pc_from_py(const py::handle& h) {
  if (py::isinstance<cf::Pc>(h)) return h.cast<cf::Pc>();
  if (py::isinstance<py::str>(h)) {
    const std::string s = h.cast<std::string>();
    const std::optional<cf::Pc> pc = cf::pc_from_string(s);
    if (!pc)
      fail("not a PC: '" + s + "' (expected 'type:a:b' with type f-f, e-f, f-e, v-f, f-v or e-e)");
    return *pc;
  }
  if (py::isinstance<py::tuple>(h) && py::len(h) == 3) {
    const py::tuple t = py::reinterpret_borrow<py::tuple>(h);
    if (py::isinstance<py::str>(t[0])) {
      const std::optional<cf::PcType> type = cf::pc_type_from_string(t[0].cast<std::string>());
      if (!type)
        fail("not a PC type: '" + t[0].cast<std::string>() + "' (f-f, e-f, f-e, v-f, f-v or e-e)");
      try {
        return cf::Pc{*type, t[1].cast<std::int32_t>(), t[2].cast<std::int32_t>()};
      } catch (const py::cast_error&) {
      }
    }
  }
  fail("not a PC: " + std::string(py::repr(h)) +
       " (expected 'type:a:b', a (type, a, b) tuple or a cf.Pc)");
}

cf::PcSet pcset_from_py(const py::handle& h) {
  std::vector<cf::Pc> pcs;
  if (py::isinstance<py::str>(h)) {
    const std::string s = h.cast<std::string>();
    std::size_t start = 0;
    while (start <= s.size() && !s.empty()) {
      const std::size_t semi = s.find(';', start);
      pcs.push_back(pc_from_py(
          py::str(s.substr(start, semi == std::string::npos ? std::string::npos : semi - start))));
      if (semi == std::string::npos) break;
      start = semi + 1;
    }
  } else if (py::isinstance<cf::Pc>(h) || py::isinstance<py::tuple>(h)) {
    // A single PC given alone, or a (type, a, b) tuple.
    if (py::isinstance<py::tuple>(h) && py::len(h) == 3 &&
        py::isinstance<py::str>(py::reinterpret_borrow<py::tuple>(h)[0]))
      pcs.push_back(pc_from_py(h));
    else if (py::isinstance<cf::Pc>(h))
      pcs.push_back(pc_from_py(h));
    else
      for (const py::handle& x : h) pcs.push_back(pc_from_py(x));
  } else if (py::isinstance<py::sequence>(h)) {
    for (const py::handle& x : h) pcs.push_back(pc_from_py(x));
  } else {
    fail("not a set of PCs: " + std::string(py::repr(h)) +
         " (expected 'type:a:b;...' or a list of PCs)");
  }
  if (pcs.empty()) fail("a set of PCs needs 1 to 3 PCs, got none");
  return cf::PcSet(pcs);  // throws cf::Error for more than 3 or a repeat
}

std::vector<cf::Pc> pcs_to_py(const cf::PcSet& pcs) { return {pcs.begin(), pcs.end()}; }

}  // namespace cfpy

PYBIND11_MODULE(_cf, m) {
  namespace py = pybind11;
  using namespace cfpy;
  m.doc() =
      "cf: contact formations of two rigid polyhedra (libcf), the C++ extension of the package cf.";
  m.attr("__version__") = cf::kVersion;  // the project's version (cmake/version.cmake)
  m.attr("graph_format_version") = cf::kGraphFormatVersion;

  py::register_exception<cf::Error>(m, "Error", PyExc_ValueError).doc() =
      "Bad input (a file, a model, a graph, a trajectory, a parameter): a ValueError whose message "
      "is libcf's.";
  // cf.FileError: a cf.Error and an OSError, for a file that cannot be read or written as such
  // (cf::FileError). Registered after cf.Error, so that its translator is tried first.
  static PyObject* file_error = nullptr;
  {
    const py::tuple bases = py::make_tuple(m.attr("Error"), py::handle(PyExc_OSError));
    file_error = PyErr_NewExceptionWithDoc(
        "cf._cf.FileError",
        "A file that cannot be read or written as such (missing, a FIFO, a device, an input of "
        "the run, no such directory): both a cf.Error and an OSError, with the tools' message.",
        bases.ptr(), nullptr);
    if (file_error == nullptr) throw py::error_already_set();
    m.attr("FileError") = py::handle(file_error);
  }
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const cf::FileError& e) {
      PyErr_SetString(file_error, e.what());
    }
  });

  py::class_<cf::Pc>(m, "Pc",
                     "A principal contact: a PC type and the indices of A's and B's elements.")
      .def(py::init([](const py::object& spec) { return pc_from_py(spec); }), py::arg("spec"),
           "From 'type:a:b' (e.g. 'e-f:4:4') or a (type, a, b) tuple.")
      .def(py::init([](const std::string& type, int a, int b) {
             return pc_from_py(py::make_tuple(type, a, b));
           }),
           py::arg("type"), py::arg("a"), py::arg("b"))
      .def_property_readonly(
          "type", [](const cf::Pc& pc) { return std::string(cf::to_string(pc.type)); },
          "'f-f', 'e-f', 'f-e', 'v-f', 'f-v' or 'e-e' (A's element kind, then B's)")
      .def_readonly("a", &cf::Pc::a, "index of A's element (of the kind the type names)")
      .def_readonly("b", &cf::Pc::b, "index of B's element")
      .def("__str__", [](const cf::Pc& pc) { return cf::to_string(pc); })
      .def("__repr__", [](const cf::Pc& pc) { return "cf.Pc('" + cf::to_string(pc) + "')"; })
      .def("__eq__",
           [](const cf::Pc& x, const py::object& y) {
             try {
               return x == pc_from_py(y);
             } catch (const cf::Error&) {
               return false;
             }
           })
      .def("__lt__", [](const cf::Pc& x, const cf::Pc& y) { return x < y; })
      .def("__hash__", [](const cf::Pc& pc) { return py::hash(py::str(cf::to_string(pc))); })
      .def(py::pickle([](const cf::Pc& pc) { return cf::to_string(pc); },
                      [](const std::string& s) { return pc_from_py(py::str(s)); }));

  py::class_<cf::Params>(
      m, "Params",
      "Parameters of the renderer (cf::Params): the same names and units as in C++. "
      "Params(**kwargs) starts from the defaults (the paper's values).")
      .def(py::init(
          [](const py::kwargs& kw) { return params_from_kwargs(cf::Params(), kw, "Params"); }))
      .def(
          "replace",
          [](const cf::Params& P, const py::kwargs& kw) {
            return params_from_kwargs(P, kw, "Params.replace");
          },
          "A copy with the given fields changed.")
      .def("to_dict", &params_to_dict,
           "Every field by name (enums as strings, moment_point_A as an array).")
      .def("__getattr__",
           [](const cf::Params& P, const std::string& name) -> py::object {
             py::dict d = params_to_dict(P);
             if (d.contains(name)) return d[py::str(name)];
             throw py::attribute_error("cf.Params has no field '" + name + "'");
           })
      .def("__repr__", [](const cf::Params& P) {
        std::string s = "cf.Params(";
        bool first = true;
        for (const auto& [k, v] : params_to_dict(P)) {
          s += (first ? "" : ", ") + k.cast<std::string>() + "=" + std::string(py::repr(v));
          first = false;
        }
        return s + ")";
      });

  bind_graph(m);
  bind_render(m);
  add_text_signatures(m);
}
