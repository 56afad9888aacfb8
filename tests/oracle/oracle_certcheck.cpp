// oracle_certcheck G.json C.json [--verbose]: rechecks cfgen's certificates of invalidity
// (docs/certificates.md) with the independent oracle. One summary line, then every file
// problem and every rejected set (with --verbose also warnings and every set's verdict).
// Exit 0: nothing rejected; 1: something rejected; 2: unreadable input or a usage mistake.

#include "certificate_check.hpp"

#include <iostream>
#include <string>

int main(int argc, char** argv) {
  std::string graph, cert;
  bool verbose = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--verbose" || a == "-v") {
      verbose = true;
    } else if (a == "--help" || a == "-h") {
      std::cout << "usage: oracle_certcheck G.json C.json [--verbose]\n";
      return 0;
    } else if (!a.empty() && a[0] == '-') {
      std::cerr << "oracle_certcheck: unknown option " << a << "\n";
      return 2;
    } else if (graph.empty()) {
      graph = a;
    } else if (cert.empty()) {
      cert = a;
    } else {
      std::cerr << "oracle_certcheck: too many arguments\n";
      return 2;
    }
  }
  if (cert.empty()) {
    std::cerr << "usage: oracle_certcheck G.json C.json [--verbose]\n";
    return 2;
  }
  oracle::CertificateReport rep;
  try {
    rep = oracle::check_certificate_files(graph, cert);
  } catch (const std::exception& e) {
    std::cerr << "oracle_certcheck: " << e.what() << "\n";
    return 2;
  }
  std::cout << rep.summary_line() << "\n";
  for (const auto& line : rep.rejection_lines()) std::cout << line << "\n";
  if (verbose) {
    for (const auto& w : rep.warnings) std::cout << "warning: " << w << "\n";
    for (const auto& s : rep.sets) {
      std::cout << "set " << s.index << " {" << s.pcs << "} " << s.kind << ": "
                << oracle::outcome_name(s.outcome);
      if (!s.reason.empty()) std::cout << " (" << s.reason << ")";
      std::cout << "\n";
    }
  }
  return rep.passed() ? 0 : 1;
}
