// cf.Polyhedron, cf.Cf, cf.CfGraph and cf.load_graph.

#include "common.hpp"

#include <cstdint>
#include <cstring>
#include <optional>
#include <tuple>
#include <type_traits>

namespace cfpy {

namespace {

/// One CF of a graph with its id (CfRecord has none).
struct CfEntry {
  int id = -1;
  cf::CfRecord rec;
};

cf::CfId checked_id(const cf::CfGraph& g, long id, const char* where) {
  if (id < 0 || static_cast<std::size_t>(id) >= g.num_cfs())
    fail(std::string(where) + ": no CF " + std::to_string(id) + " in the graph (ids 0.." +
         std::to_string(static_cast<long>(g.num_cfs()) - 1) + ")");
  return cf::CfId(static_cast<std::int32_t>(id));
}

template <class T>
py::array_t<T> array2(std::size_t rows, std::size_t cols) {
  return py::array_t<T>(
      std::vector<py::ssize_t>{static_cast<py::ssize_t>(rows), static_cast<py::ssize_t>(cols)});
}

py::array_t<double> vec(const cf::Vec3& v) { return py::array_t<double>(3, v.data()); }

// A read-only numpy view of memory that `owner` (the Python object holding it) keeps alive:
// no copy. `first` is the first element; `stride` the bytes from one row to the next (a
// record's size: the rows are a member of each record); `cols` values per row, `col_stride`
// bytes apart (0 cols: one value per row, a 1-D view).
template <class T>
py::array_t<T> view(const T* first, std::size_t rows, std::size_t stride, std::size_t cols,
                    std::ptrdiff_t col_stride, const py::handle& owner) {
  std::vector<py::ssize_t> shape{static_cast<py::ssize_t>(rows)};
  std::vector<py::ssize_t> strides{static_cast<py::ssize_t>(stride)};
  if (cols > 0) shape.push_back(static_cast<py::ssize_t>(cols)), strides.push_back(col_stride);
  if (rows == 0) return py::array_t<T>(shape);  // nothing to share
  py::array_t<T> a(shape, strides, first, owner);
  a.attr("setflags")(py::arg("write") = false);
  return a;
}

// Bytes from member `a` to member `b` of one record.
template <class A, class B>
std::ptrdiff_t member_gap(const A& a, const B& b) {
  return reinterpret_cast<const char*>(&b) - reinterpret_cast<const char*>(&a);
}

// The int32 value of an id, in place: ids are one int32 (cf/types.hpp).
template <class Id>
const std::int32_t* id_data(const Id& id) {
  static_assert(sizeof(Id) == sizeof(std::int32_t) && std::is_standard_layout_v<Id>);
  return reinterpret_cast<const std::int32_t*>(&id);
}

py::array_t<double> quaternion_wxyz(const cf::Mat3& R) {
  Eigen::Quaterniond q(R);
  q.normalize();
  if (q.w() < 0) q.coeffs() *= -1;
  const double wxyz[4] = {q.w(), q.x(), q.y(), q.z()};
  return py::array_t<double>(4, wxyz);
}

// A stored count, None (std::nullopt) when the file does not store it (-1).
std::optional<int> optional_int(int v) { return v < 0 ? std::nullopt : std::optional<int>(v); }

using cf::Polyhedron;

// cf.Polyhedron's faces' planes, areas and centroids, mass properties, JSON and repr.
void add_polyhedron_faces(py::class_<Polyhedron>& cls) {
  // Views of the faces' records (no copy), kept alive by the model.
  auto faces = [](const py::object& self) -> const std::vector<cf::Face>& {
    return self.cast<const Polyhedron&>().faces();
  };
  cls.def_property_readonly(
         "face_normals",
         [faces](const py::object& self) {
           const auto& F = faces(self);
           return view(F.empty() ? nullptr : F[0].normal.data(), F.size(), sizeof(cf::Face), 3,
                       sizeof(double), self);
         },
         "(F, 3) float64: outward unit normals (a read-only view of the model, no copy).")
      .def_property_readonly(
          "face_offsets",
          [faces](const py::object& self) {
            const auto& F = faces(self);
            return view(F.empty() ? nullptr : &F[0].offset, F.size(), sizeof(cf::Face), 0, 0, self);
          },
          "(F,) float64: plane offsets, mm (normal . x == offset); a read-only view.")
      .def_property_readonly(
          "face_areas",
          [faces](const py::object& self) {
            const auto& F = faces(self);
            return view(F.empty() ? nullptr : &F[0].area, F.size(), sizeof(cf::Face), 0, 0, self);
          },
          "(F,) float64: areas, mm^2, holes excluded; a read-only view.")
      .def_property_readonly(
          "face_centroids",
          [faces](const py::object& self) {
            const auto& F = faces(self);
            return view(F.empty() ? nullptr : F[0].centroid.data(), F.size(), sizeof(cf::Face), 3,
                        sizeof(double), self);
          },
          "(F, 3) float64: area centroids, mm; a read-only view.")
      .def_property_readonly("volume", &Polyhedron::volume, "mm^3")
      .def_property_readonly("size", &Polyhedron::size, "mm, the bounding box's diagonal")
      .def_property_readonly(
          "vertex_centroid", [](const Polyhedron& P) { return vec(P.vertex_centroid()); },
          "mm, the mean of the vertices (the paper's centroid)")
      .def_property_readonly(
          "volume_centroid", [](const Polyhedron& P) { return vec(P.volume_centroid()); },
          "mm, the centroid of the uniform solid")
      .def_property_readonly("bbox_min", [](const Polyhedron& P) { return vec(P.bbox_min()); })
      .def_property_readonly("bbox_max", [](const Polyhedron& P) { return vec(P.bbox_max()); })
      .def(
          "to_json", [](const Polyhedron& P, int indent) { return cf::to_json(P, indent); },
          py::arg("indent") = 2,
          "The model object of the graph file (docs/spec.md, section 5), as cfgen --features "
          "prints it.")
      .def("__repr__", [](const Polyhedron& P) {
        return "<cf.Polyhedron '" + P.name() + "': " + std::to_string(P.num_vertices()) +
               " vertices, " + std::to_string(P.num_edges()) + " edges, " +
               std::to_string(P.num_faces()) + " faces>";
      });
}

// cf.Polyhedron: its counts, vertices, edges, faces (loops) and edge properties.
void bind_polyhedron(py::module_& m) {
  auto cls =
      py::class_<Polyhedron>(
          m, "Polyhedron",
          "A featured polyhedron (cf::Polyhedron): faces, edges and vertices in mm, indexed as "
          "in the graph's PCs (docs/features.md).")
          .def_property_readonly("name", &Polyhedron::name)
          .def_property_readonly("num_vertices", &Polyhedron::num_vertices)
          .def_property_readonly("num_edges", &Polyhedron::num_edges)
          .def_property_readonly("num_faces", &Polyhedron::num_faces)
          .def_property_readonly(
              "vertices",
              [](const py::object& self) {
                const auto& V = self.cast<const Polyhedron&>().vertices();
                return view(V.empty() ? nullptr : V[0].p.data(), V.size(), sizeof(cf::Vertex), 3,
                            sizeof(double), self);
              },
              "(V, 3) float64: the feature vertices, mm, model frame (a read-only view of the "
              "model, no copy).")
          .def_property_readonly(
              "edges",
              [](const py::object& self) {
                const auto& E = self.cast<const Polyhedron&>().edges();
                if (E.empty()) return array2<std::int32_t>(0, 2);
                return view(id_data(E[0].v0), E.size(), sizeof(cf::Edge), 2,
                            member_gap(E[0].v0, E[0].v1), self);
              },
              "(E, 2) int32: each edge's end vertices v0 < v1; a read-only view.")
          .def_property_readonly(
              "faces",
              [](const py::object& self) {
                std::vector<std::vector<py::array_t<std::int32_t>>> faces;
                for (const cf::Face& f : self.cast<const Polyhedron&>().faces()) {
                  faces.emplace_back();
                  for (const auto& loop : f.loops)  // a loop has 3 vertices or more
                    faces.back().push_back(
                        view(id_data(loop[0]), loop.size(), sizeof(loop[0]), 0, 0, self));
                }
                return faces;
              },
              "Per face, its loops as int32 arrays of vertex indices: the outer boundary first "
              "(counter-clockwise seen from outside), then the holes; read-only views.")
          .def_property_readonly(
              "edge_faces",
              [](const py::object& self) {
                const auto& E = self.cast<const Polyhedron&>().edges();
                if (E.empty()) return array2<std::int32_t>(0, 2);
                return view(id_data(E[0].left), E.size(), sizeof(cf::Edge), 2,
                            member_gap(E[0].left, E[0].right), self);
              },
              "(E, 2) int32: each edge's left face (its loop runs v0 -> v1) and right face; a "
              "read-only view.")
          .def_property_readonly(
              "edge_convex",
              [](const py::object& self) {
                const auto& E = self.cast<const Polyhedron&>().edges();
                return view(E.empty() ? nullptr : &E[0].convex, E.size(), sizeof(cf::Edge), 0, 0,
                            self);
              },
              "(E,) bool: interior dihedral angle below pi; a read-only view.")
          .def_property_readonly(
              "edge_dihedral",
              [](const py::object& self) {
                const auto& E = self.cast<const Polyhedron&>().edges();
                return view(E.empty() ? nullptr : &E[0].dihedral, E.size(), sizeof(cf::Edge), 0, 0,
                            self);
              },
              "(E,) float64: interior dihedral angles, rad; a read-only view.");
  add_polyhedron_faces(cls);
}

// cf.Cf: one CF with its id, PCs, witness and freedoms.
void bind_cf(py::module_& m) {
  py::class_<CfEntry>(m, "Cf", "One contact formation of a graph (cf::CfRecord) with its id.")
      .def_readonly("id", &CfEntry::id)
      .def_property_readonly(
          "pcs", [](const CfEntry& e) { return pcs_to_py(e.rec.pcs); },
          "The PCs (1 to 3 cf.Pc) in canonical order.")
      .def_property_readonly(
          "pcs_string", [](const CfEntry& e) { return cf::to_string(e.rec.pcs); },
          "The PCs as 'type:a:b;...' (cfreplay's pcs column).")
      .def_property_readonly(
          "witness_R",
          [](const py::object& self) {
            // Eigen stores the matrix by columns: row i, column j at (i + 3 j) doubles.
            const cf::Mat3& R = self.cast<const CfEntry&>().rec.witness.R_BA;
            return view(R.data(), 3, sizeof(double), 3, 3 * sizeof(double), self);
          },
          "(3, 3): the witness pose's rotation R (x_B = R x_A + t); a read-only view of the "
          "CF, no copy.")
      .def_property_readonly(
          "witness_t",
          [](const py::object& self) {
            const cf::Vec3& t = self.cast<const CfEntry&>().rec.witness.t_BA;
            return view(t.data(), 3, sizeof(double), 0, 0, self);
          },
          "(3,): the witness pose's translation t, mm; a read-only view.")
      .def_property_readonly(
          "witness_q", [](const CfEntry& e) { return quaternion_wxyz(e.rec.witness.R_BA); },
          "(4,): the witness rotation as a unit quaternion w, x, y, z (w >= 0).")
      .def_property_readonly(
          "dof", [](const CfEntry& e) { return optional_int(e.rec.dof); },
          "Freedoms at the witness (0..6), None when the file does not store them.")
      .def_property_readonly(
          "translation_dof", [](const CfEntry& e) { return optional_int(e.rec.translation_dof); },
          "Pure translations among the freedoms (0..3), None when not stored.")
      .def_property_readonly(
          "pure_rotation",
          [](const CfEntry& e) {
            return e.rec.dof < 0 ? std::nullopt : std::optional<bool>(e.rec.pure_rotation);
          },
          "Whether some pure rotation keeps the CF; None when the freedoms are not stored.")
      .def_property_readonly(
          "planes",
          [](const py::object& self) {
            const cf::CfRecord& r = self.cast<const CfEntry&>().rec;
            return view(r.planes[0].data(), static_cast<std::size_t>(r.num_planes),
                        sizeof(r.planes[0]), 4, sizeof(double), self);
          },
          "(n, 4): each PC's contact plane at the witness (n_x, n_y, n_z, d), n into A; (0, 4) "
          "when not stored. A read-only view.")
      .def("__repr__", [](const CfEntry& e) {
        return "<cf.Cf " + std::to_string(e.id) + ": " + cf::to_string(e.rec.pcs) + ">";
      });
}

// cf.CfGraph's transitions: neighbours, transitions from a CF, adjacency, all as arrays.
void add_graph_transitions(py::class_<cf::CfGraph>& cls) {
  cls.def(
         "neighbours",
         [](const cf::CfGraph& g, long id, const std::optional<std::string>& kind) {
           const cf::CfId c = checked_id(g, id, "neighbours");
           std::optional<cf::TransitionKind> k;
           if (kind) {
             k = cf::transition_kind_from_string(*kind);
             if (!k)
               fail("neighbours: kind must be 'gain', 'lose' or 'change', got '" + *kind + "'");
           }
           std::vector<int> out;
           for (const cf::Transition& t : g.out_transitions(c))
             if (!k || t.kind == *k) out.push_back(t.to.value());
           return out;
         },
         py::arg("id"), py::arg("kind") = py::none(),
         "Ids of the CFs one transition away from `id` (sorted), all or only of one kind "
         "('gain', 'lose', 'change').")
      .def(
          "transitions_from",
          [](const cf::CfGraph& g, long id) {
            std::vector<std::pair<int, std::string>> out;
            for (const cf::Transition& t : g.out_transitions(checked_id(g, id, "transitions_from")))
              out.emplace_back(t.to.value(), cf::to_string(t.kind));
            return out;
          },
          py::arg("id"), "The transitions leaving `id` as (to, kind) pairs, sorted by target.")
      .def(
          "adjacent",
          [](const cf::CfGraph& g, long from, long to) {
            return g.adjacent(cf::CfId(static_cast<std::int32_t>(from)),
                              cf::CfId(static_cast<std::int32_t>(to)));
          },
          py::arg("from_id"), py::arg("to_id"),
          "True when the graph has a transition from one to the other.")
      .def(
          "transition_arrays",
          [](const cf::CfGraph& g) {
            const auto n = static_cast<py::ssize_t>(g.num_transitions());
            py::array_t<std::int32_t> from(n), to(n);
            py::list kinds;
            for (py::ssize_t i = 0; i < n; ++i) {
              const cf::Transition& t = g.transition(static_cast<std::size_t>(i));
              from.mutable_at(i) = t.from.value();
              to.mutable_at(i) = t.to.value();
              kinds.append(cf::to_string(t.kind));
            }
            return std::make_tuple(from, to,
                                   py::array(py::module_::import("numpy").attr("array")(kinds)));
          },
          "Every transition in file order as three arrays: from (int32), to (int32), kind (str).");
}

// cf.CfGraph: models, CFs and their queries, transitions, metadata, JSON, saving.
void bind_cf_graph(py::module_& m) {
  auto cls =
      py::class_<cf::CfGraph>(
          m, "CfGraph", py::dynamic_attr(),
          "The CF graph of a model pair (cf::CfGraph): CFs, transitions and the two models. "
          "Immutable; load it with cf.load_graph or make it with cf.gen.generate.")
          .def_property_readonly("model_a", &cf::CfGraph::model_a,
                                 py::return_value_policy::reference_internal,
                                 "A, the moving polyhedron.")
          .def_property_readonly("model_b", &cf::CfGraph::model_b,
                                 py::return_value_policy::reference_internal,
                                 "B, the fixed polyhedron (world frame).")
          .def_property_readonly("num_cfs", &cf::CfGraph::num_cfs)
          .def_property_readonly("num_transitions", &cf::CfGraph::num_transitions)
          .def("__len__", &cf::CfGraph::num_cfs)
          .def(
              "cf",
              [](const cf::CfGraph& g, long id) {
                return CfEntry{static_cast<int>(id), g.cf(checked_id(g, id, "cf"))};
              },
              py::arg("id"), "The CF with this id (cf.Error when there is none).")
          .def_property_readonly(
              "cfs",
              [](const cf::CfGraph& g) {
                std::vector<CfEntry> out;
                out.reserve(g.num_cfs());
                for (std::size_t i = 0; i < g.num_cfs(); ++i)
                  out.push_back(
                      CfEntry{static_cast<int>(i), g.cf(cf::CfId(static_cast<std::int32_t>(i)))});
                return out;
              },
              "Every CF, in id order.")
          .def(
              "cf_of",
              [](const cf::CfGraph& g, const py::object& pcs) -> std::optional<int> {
                const std::optional<cf::CfId> id = g.find(pcset_from_py(pcs));
                return id ? std::optional<int>(id->value()) : std::nullopt;
              },
              py::arg("pcs"),
              "The id of the CF with exactly these PCs ('type:a:b;...', or a list of PCs in any "
              "order), "
              "None when the graph has none.")
          .def(
              "holds",
              [](const cf::CfGraph& g, const py::object& pc) { return g.holds(pc_from_py(pc)); },
              py::arg("pc"), "True when some CF of the graph holds this PC.");
  add_graph_transitions(cls);
  cls.def_property_readonly(
         "metadata_json", &cf::CfGraph::metadata_json,
         "The file's extra top-level members (statistics, parameters) as JSON text.")
      .def("to_json", &cf::CfGraph::to_json, py::arg("indent") = -1, "The graph file's JSON text.")
      .def("_save", &cf::CfGraph::save, py::arg("path"),
           "Writes the graph (JSON, or CBOR when the name ends in .cbor), whole or not at all.")
      .def("__repr__", [](const cf::CfGraph& g) {
        return "<cf.CfGraph '" + g.model_a().name() + "' against '" + g.model_b().name() +
               "': " + std::to_string(g.num_cfs()) + " CFs, " +
               std::to_string(g.num_transitions()) + " transitions>";
      });
}

}  // namespace

void bind_graph(py::module_& m) {
  bind_polyhedron(m);
  bind_cf(m);
  bind_cf_graph(m);
  m.def(
      "load_graph",
      [](const std::string& path, bool validate_schema, bool full_schema_check) {
        cf::GraphLoadOptions o;
        o.validate_schema = validate_schema;
        o.full_schema_check = full_schema_check;
        py::gil_scoped_release release;
        return cf::CfGraph::load(path, o);
      },
      py::arg("path"), py::arg("validate_schema") = true, py::arg("full_schema_check") = false,
      "Loads a CF graph file (JSON, or CBOR when the name ends in .cbor) and checks it against the "
      "schema and for consistency (cf::CfGraph::load). Raises cf.Error naming the file, the JSON "
      "pointer and the problem.");
}

}  // namespace cfpy
