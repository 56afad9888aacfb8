// cfinspect --html: the browser viewer of a CF graph as one self-contained HTML page (the
// bundled page from viewer/, with the graph and an optional replay put into it as JSON).
#pragma once

#include <cstddef>
#include <string>

namespace cf::inspect {

/// The viewer page with the marker <!--CF_DATA--> for the data, generated at build time by
/// viewer/build.mjs; nullptr when cfinspect was built without Node.js and the npm packages.
const char* viewer_page();

struct ViewerInputs {
  std::string graph_path;       // shown as the page's title
  std::string graph_json;       // the graph document (JSON text)
  std::size_t num_cfs = 0;      // to check the replay's CF ids
  std::string replay_path;      // cfreplay's output CSV, optional
  std::string trajectory_path;  // the poses that replay ran on, optional (animates A)
  long long initial_cf = -1;    // CF shown first (-1: CF 0)
};

/// The whole page. Reads and checks the replay and trajectory files.
/// @throws cf::Error naming the file, the line and the problem.
std::string viewer_html(const ViewerInputs& in);

/// The text of a regular file, refusing directories, devices and FIFOs before opening.
/// @throws cf::Error "<what> '<path>': <reason>".
std::string read_text_file(const std::string& path, const char* what);

}  // namespace cf::inspect
