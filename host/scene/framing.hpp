#pragma once
// The camera a scene gets when it names none: it frames the fluid's extent over the run.
#include "scene/scene.hpp"

namespace pbflow {

// Looks at the box the fluid may fill (the domain's floor, up to a quarter above the fluid's
// highest start, where gravity is -y; else the whole domain) from the front (+z) and 30
// degrees above, as close as fits the box's corners in a 16:9 image (the default 1280x720)
// at the scene's vertical field of view.
Camera framing_camera(const Scene& scene);

}  // namespace pbflow
