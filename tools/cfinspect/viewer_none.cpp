// viewer_page() of a cfinspect built without Node.js and the viewer's npm packages.
#include "html.hpp"

namespace cf::inspect {

const char* viewer_page() { return nullptr; }

}  // namespace cf::inspect
