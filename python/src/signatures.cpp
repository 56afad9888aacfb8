// Text signatures for inspect.signature: CPython reads a builtin function's signature from a
// doc that starts with "name(params)\n--\n\n". pybind11 starts its docs with the typed
// signature instead ("name(a: int, b: str = 'mm') -> None"), which inspect cannot read.
// Each function's doc is rewritten once, after the bindings: the text signature (names and
// defaults), then pybind11's typed line (which help() and the stub generator read), then
// the doc. Overloaded functions keep pybind11's doc: they have no one signature.

#include "common.hpp"

#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace cfpy {
namespace {

// The parameters of pybind11's typed signature, split at the commas outside brackets and
// quotes: "self: cf._cf.Cf, kind: Optional[str] = None" -> {"self: cf._cf.Cf", ...}.
std::vector<std::string> split_params(const std::string& s) {
  std::vector<std::string> out;
  std::string cur;
  int depth = 0;
  char quote = 0;
  for (char c : s) {
    if (quote) {
      quote = c == quote ? 0 : quote;
    } else if (c == '\'' || c == '"') {
      quote = c;
    } else if (c == '[' || c == '(' || c == '{') {
      ++depth;
    } else if (c == ']' || c == ')' || c == '}') {
      --depth;
    } else if (c == ',' && depth == 0) {
      out.push_back(cur);
      cur.clear();
      continue;
    }
    cur += c;
  }
  if (!cur.empty()) out.push_back(cur);
  return out;
}

std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(' ');
  const auto b = s.find_last_not_of(' ');
  return a == std::string::npos ? "" : s.substr(a, b - a + 1);
}

// "t: float" -> "t"; "units: str = 'mm'" -> "units='mm'"; "*args" and "**kwargs" as they are.
std::string untyped(const std::string& param) {
  const std::string p = trim(param);
  const auto colon = p.find(':');
  if (colon == std::string::npos) return p;
  const auto eq = p.find(" = ", colon);
  return trim(p.substr(0, colon)) + (eq == std::string::npos ? "" : "=" + trim(p.substr(eq + 3)));
}

// The new doc of a function whose pybind11 doc is `doc`, or "" to leave it.
std::string with_text_signature(const std::string& doc) {
  const auto open = doc.find('(');
  const auto eol = doc.find('\n');
  const std::string first = doc.substr(0, eol);
  const auto arrow = first.rfind(") -> ");
  if (open == std::string::npos || arrow == std::string::npos || arrow < open ||
      doc.find("Overloaded function.") != std::string::npos)
    return "";
  std::string sig;
  for (const std::string& p : split_params(first.substr(open + 1, arrow - open - 1)))
    sig += (sig.empty() ? "" : ", ") + untyped(p);
  const std::string rest = eol == std::string::npos ? "" : doc.substr(eol);
  return first.substr(0, open) + "(" + sig + ")\n--\n\n" + first + rest;
}

void rewrite(PyObject* f) {
  if (!PyCFunction_Check(f)) return;
  PyMethodDef* def = reinterpret_cast<PyCFunctionObject*>(f)->m_ml;
  if (def->ml_doc == nullptr) return;
  const std::string doc = with_text_signature(def->ml_doc);
  if (doc.empty()) return;
  // pybind11 allocates each function's doc with strdup and frees it with the function.
  char* old = const_cast<char*>(def->ml_doc);
  def->ml_doc = strdup(doc.c_str());
  std::free(old);
}

}  // namespace

void add_text_signatures(py::module_& m) {
  const std::string name = py::str(m.attr("__name__"));
  for (auto item : py::reinterpret_borrow<py::dict>(m.attr("__dict__"))) {
    py::handle v = item.second;
    if (PyType_Check(v.ptr()) && py::str(v.attr("__module__")).cast<std::string>() == name) {
      // A class's __dict__ is a mappingproxy: copied into a dict to walk it.
      for (auto member : py::dict(v.attr("__dict__"))) {
        py::handle f = member.second;
        if (PyInstanceMethod_Check(f.ptr()))
          rewrite(PyInstanceMethod_GET_FUNCTION(f.ptr()));
        else if (py::hasattr(f, "__func__"))  // a staticmethod
          rewrite(f.attr("__func__").ptr());
      }
    } else {
      rewrite(v.ptr());
    }
  }
}

}  // namespace cfpy
