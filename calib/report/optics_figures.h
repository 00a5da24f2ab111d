// The figures of the characterize job (model/design/characterize.h), in the spirit of the
// seed paper's Figs. 4-9: fig04_ray_trace.png (rays, virtual images, depth of field),
// fig05_image_height.png, fig06_viewpoints.png, fig07_area_aspect.png,
// fig08_image_forming.png, fig09_blur.png, written into out_dir. Throws InputError naming
// the path when a file cannot be written.
#pragma once

#include <string>

#include "model/design/characterize.h"

namespace omnical {

void WriteCharacterizeFigures(const CharacterizeResult& result, const std::string& out_dir);

}  // namespace omnical
