#pragma once
// Draws particles from a GL buffer in the solver's frame layout (solver.hpp) into an
// off-screen image: lit spheres (particles, density, speed styles) or a screen-space
// fluid surface (fluid style), over the domain's floor and walls.
#include <cstdint>
#include <string>
#include <vector>

#include "capture/gl_objects.hpp"
#include "scene/scene.hpp"
#include "sim/solver.hpp"

namespace pbflow::capture {

// Normals: the fluid style's surface as unit normals in the tank's frame, RGB = 0.5 n + 0.5, black
// where there is no fluid (the debug view of the surface; the rendering tests read it).
enum class Style { Fluid, Particles, Density, Speed, Normals };
inline constexpr Style kStyles[] = {Style::Fluid, Style::Particles, Style::Density, Style::Speed, Style::Normals};
// The styles that draw the fluid's surface (from the smoothed positions), not its particles.
inline bool draws_surface(Style s) { return s == Style::Fluid || s == Style::Normals; }
// The styles that draw white water over it (the normals style is the surface's debug view).
inline bool draws_white_water(Style s) { return s == Style::Fluid; }
// What the solver must produce for frames drawn in `style` (none: nothing drawn) and, where
// `exported`, written out: the one place that decides it (Solver::set_outputs).
inline FrameOutputs frame_outputs(const Style* drawn, bool exported) {
  return {drawn && draws_surface(*drawn), exported || (drawn && draws_white_water(*drawn))};
}
Style parse_style(const std::string& name);  // throws InputError naming the choices
const char* style_name(Style style);

// Colour scale of the density style: compression c_i from 0 (blue) to this (red).
constexpr double kDensityScale = 0.03;

struct View {
  int width = 1280, height = 720;
  Style style = Style::Fluid;
  Camera camera;
  Box domain;
  std::vector<Obstacle> obstacles;  // drawn as solids, in the tank's frame
  Pose tank;  // where the tank stands in the world (Solver::tank_pose): all is drawn from its frame
  double particle_radius = 0.01;  // m
  double rest_density = 1000;     // kg/m^3, for the density style
  double speed_scale = 1;         // m/s drawn red in the speed style
  // Fluid style: the surface's depth, thickness and smoothing run at 1/surface_divisor of
  // the image's width and height (1 or 2), the shading at full size. Those three stages
  // are fragment-bound, most of a fluid frame's cost on a CPU device.
  int surface_divisor = 2;
};

// The picture's axes in the world, seen from `c`: forward from the eye to the target, up +y
// unless the camera looks (nearly) along it (then the image's up is -z, as on a map), right.
struct CameraAxes {
  glm::dvec3 right, up, forward;
};
CameraAxes camera_axes(const Camera& c);

// RGB, 8 bits per channel, rows from the top.
struct Image {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;
};

class Renderer {
 public:
  explicit Renderer(const View& view);  // needs a current gl::Context

  // Draws `count` particles from `buffer` (frame layout, room for `white_capacity` white water
  // particles, drawn in the fluid style); count 0 draws the empty tank.
  // The image is the renderer's own, valid until the next call: every frame's pixels
  // fill the same memory, which page faults made dear to allocate anew (host/app/main.cpp).
  const Image& render(GLuint buffer, uint32_t count, uint32_t white_capacity = 0);
  const View& view() const { return view_; }
  void set_camera(const Camera& camera);  // the next render() draws from here
  // Where the tank and the obstacles in it stand now (Solver::tank_pose, obstacle_poses): the
  // next render() draws them there.
  void set_poses(const Pose& tank, const std::vector<Pose>& obstacles);
  // The GPU time of the last render() (a GL timer query), the read-back excluded: what a
  // frame costs the GPU, where the wall clock also counts the driver and the copy out.
  double last_gpu_seconds() const { return last_gpu_seconds_; }

 private:
  struct FrameUniforms;
  // viewport: the pass's size; white: the frame's room for white water
  FrameUniforms uniforms(uint32_t count, int pass, glm::ivec2 viewport, uint32_t white = 0) const;
  void upload(const FrameUniforms& u);
  void draw_spheres(uint32_t count, int pass, glm::ivec2 viewport);
  void copy_image(GLuint from, GLuint to) const;  // a texture of the image's size
  bool surface_style() const { return draws_surface(view_.style); }
  void draw_tank_and_obstacles();  // into scene_fb_
  void upload_spheres();  // the sphere obstacles' centres, where their poses put them
  // The fluid style's surface, in compute passes over the surface's tiles (surface_tiles.glsl).
  void fluid_surface(uint32_t count);
  void run_tiles(int kind);  // the bound program, one workgroup per tile of the list `kind`
  void smooth_depth();
  void smooth_thickness();
  void surface_normals();
  void white_water(GLuint buffer, uint32_t count, uint32_t white_capacity);

  View view_;
  glm::ivec2 image_size_, surface_size_;  // the fluid surface's passes run at surface_size_
  gl::Object vao_, frame_ubo_;
  gl::Object sphere_, box_, mesh_, splat_, tile_mask_, fill_pits_, smooth_, smooth_thickness_, normals_, smooth_normals_, fluid_, white_water_;
  gl::Object scene_colour_, scene_depth_, scene_fb_;
  gl::Object output_colour_, output_depth_, output_fb_;  // a frame: the tank's image copied, then the particles
  Image image_;  // what render() returns
  gl::Object began_, drawn_;  // timestamps around the drawing
  double last_gpu_seconds_ = 0;
  std::vector<gl::Object> obstacle_spheres_;  // one particle each (frame layout), drawn at its radius
  std::vector<gl::Object> obstacle_meshes_;   // each mesh's triangles' corners, vec4s (mesh.vert)
  // The fluid surface, at surface_size_: the splat's nearest depth (float bits, atomic min;
  // read as R32F through the view) and chord sum; the smoothed depth (x into [1], y into
  // [0]), the thickness blurred (x into thickness_blur_, y into thickness_), the normals
  // (computed into [0], smoothed x into [1], y back into [0]).
  gl::Object splat_depth_, splat_depth_view_, chord_sum_, filled_depth_;
  gl::Object fluid_depth_[2], thickness_, thickness_blur_, normal_[2];
  glm::ivec2 tiles_{0};    // the surface's tiles of TILE x TILE texels (render_common.glsl)
  gl::Object tile_lists_;  // tile_mask.comp's lists and their dispatches (surface_tiles.glsl)
  bool tank_drawn_ = false;
};

}  // namespace pbflow::capture
