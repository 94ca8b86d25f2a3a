#pragma once
// The camera a scene gets when it names none: it frames the fluid's extent over the run,
// which is the domain: a splash or a jet may reach any of it (the double dam break's jet
// climbs from 0.6 to 1 m).
#include "scene/scene.hpp"

namespace pbflow {

// Looks at the domain's centre from the front (+z) and 30 degrees above, as close as fits
// its corners, wherever the tank's motion takes them, in a 16:9 image (the default 1280x720) at
// the scene's vertical field of view; with `tilt_degrees`, also with the tank turned by that
// about x or z through its floor's centre, either way (a viewer's tilt in pbflow serve).
Camera framing_camera(const Scene& scene, double tilt_degrees = 0);

}  // namespace pbflow
