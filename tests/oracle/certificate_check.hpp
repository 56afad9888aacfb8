#pragma once
// Independent checker of cfgen's certificates of invalidity (docs/certificates.md): every
// failed candidate set the certificate file lists is rechecked from the graph's models and the
// file alone, with the oracle's own geometry (poly.hpp) and exact rational arithmetic for the
// Farkas multipliers. No code is shared with tools/ or libcf/.
//
// A set is
//  - accepted when its evidence is rechecked and proves it invalid (a rule that holds, a
//    tree of cells that tiles the domain and whose every leaf claim holds, or the image under
//    a symmetry of the models of a set accepted by cells whose tree's tolerances absorb how
//    far the symmetry misses), or, for a THIN set, when its pose realises exactly the set, as
//    clear as claimed;
//  - rejected when the evidence is malformed or a claim does not hold (the reason names the
//    set's PCs, the node and what failed);
//  - not certified when its rule is evidence the checker does not accept (`finite-rotations`);
//  - undecided when the file says so.

#include "graph.hpp"

#include <nlohmann/json.hpp>

#include <array>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace oracle {

enum class CertOutcome { Accepted, Rejected, NotCertified, Undecided };
const char* outcome_name(CertOutcome o);

struct CertNodeFailure {
  int node = -1;  // node id, -1 for the tree as a whole
  std::string why;
};

struct CertSetResult {
  int index = 0;     // position in the file's `sets`
  std::string pcs;   // the file's PC list, e.g. "f-f:0:2;e-f:5:1"
  std::string kind;  // the rule's name, "cells", "image", "thin", "undecided", or "malformed"
  CertOutcome outcome = CertOutcome::Rejected;
  std::string reason;                                // one line (rejected and not certified sets)
  std::vector<CertNodeFailure> node_fails;           // cells: every node whose check failed
  std::map<std::string, std::array<int, 2>> leaves;  // cells: leaf kind -> {accepted, rejected}
};

struct CertificateReport {
  std::string graph_path, cert_path;
  std::vector<std::string> file_problems;  // header, tolerances, pieces, summary: each rejects
  std::vector<std::string> warnings;       // noted, not counted (e.g. a wrong boundary flag)
  std::vector<CertSetResult> sets;
  int accepted = 0, rejected = 0, not_certified = 0, undecided = 0;
  std::map<std::string, std::array<int, 4>> by_kind;  // kind -> counts by CertOutcome
  std::map<std::string, std::array<int, 2>> leaves;   // leaf kind -> {accepted, rejected}

  bool passed() const { return rejected == 0 && file_problems.empty(); }
  /// "sets N, accepted A, rejected R, not certified C, undecided U | by kind: ... | leaves: ..."
  std::string summary_line() const;
  /// One line per file problem and per rejected set.
  std::vector<std::string> rejection_lines() const;
};

/// Input that cannot be checked at all: a file that cannot be read or parsed, a graph whose
/// models do not rebuild, a certificate file whose `format` or `version` is not this one.
class CertificateInputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Checks a parsed certificate file against a graph. `graph_parameters` is the graph file's
/// `parameters` object (null when it has none): the certificate's tolerances must be no
/// stronger than the verifier's. Throws CertificateInputError when `format` or `version` is
/// wrong.
CertificateReport check_certificates(const Graph& g, const nlohmann::json& graph_parameters,
                                     const nlohmann::json& cert);

/// Reads both files and checks them; throws CertificateInputError naming the file and the
/// problem when either cannot be read.
CertificateReport check_certificate_files(const std::string& graph_path,
                                          const std::string& cert_path);

namespace cert {

/// An e-e PC over a node, for ee_normal_bound: A's edge direction e_A and into-face directions
/// w_A (A's frame), B's e_B and w_B (B's frame), the node's central rotation M and the turn
/// bounds beta(e_A), beta(w_A1), beta(w_A2) of the node (docs/certificates.md, "Cells").
struct EeNode {
  Mat3 M = Mat3::Identity();
  Vec3 eA = Vec3::Zero(), eB = Vec3::Zero();
  Vec3 wA[2] = {Vec3::Zero(), Vec3::Zero()}, wB[2] = {Vec3::Zero(), Vec3::Zero()};
  double beta_e = 0;
  double beta_w[2] = {0, 0};
};

/// The e-e local margin's bound by the range of the normal (docs/certificates.md, "The local
/// margin"): min(s_c + beta(e_A), G), an upper bound of the margin at every rotation of the
/// node, before the checker's final rounding allowance. Used by local-slack leaves; declared
/// here for its test.
double ee_normal_bound(const EeNode& g);

}  // namespace cert

}  // namespace oracle
