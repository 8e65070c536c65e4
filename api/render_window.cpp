#include "api/render_window.h"

#include <array>
#include <optional>

namespace penumbra::api {

void parse_render_window(const Json& value, const std::string& pointer, RenderSettings& settings,
                         Diagnostics& diag) {
  if (!value.is_array() || value.size() != 4) {
    diag.error(pointer, "must be an array of 4 integers [x0, y0, x1, y1]: pixels x0 to x1 - 1 and y0 to "
                        "y1 - 1 of the image");
    return;
  }
  // Each coordinate within the image first, so a typo names the one at fault.
  const std::array<int, 4> bounds = {settings.width, settings.height, settings.width, settings.height};
  std::array<int, 4> c{};
  bool ok = true;
  for (size_t i = 0; i < 4; ++i) {
    const auto v = read_integer(value[i], child_pointer(pointer, i), diag, Range::closed(0, bounds[i]));
    if (v) c[i] = int(*v);
    ok = ok && v.has_value();
  }
  if (!ok) return;
  const PixelWindow window{c[0], c[1], c[2], c[3]};
  if (window.x0 >= window.x1 || window.y0 >= window.y1) {
    diag.error(pointer, "must be [x0, y0, x1, y1] with x0 < x1 and y0 < y1 (x1 and y1 are exclusive); got an "
                        "empty window of " + std::to_string(window.x1 - window.x0) + "x" +
                        std::to_string(window.y1 - window.y0) + " pixels");
    return;
  }
  settings.window = window;
}

}  // namespace penumbra::api
