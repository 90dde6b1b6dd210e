// The live view in a build without GLFW (libglfw3-dev not found at configure): --view is listed
// and says why it cannot open.
#include "live_view.h"

namespace mrgi::tool {

Expected<std::unique_ptr<LiveView>> LiveView::open(const std::string&, int, int, const std::string&) {
  return fail(ErrorKind::NotFound, "--view: this mrgi was built without the live view (GLFW: install libglfw3-dev "
                                   "and configure again)");
}

}  // namespace mrgi::tool
