#include "capture/renderer.hpp"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>

#include "capture/gl_context.hpp"
#include "capture/particle_transfer.hpp"

namespace pbflow::capture {

namespace {

constexpr int kPassShaded = 0, kPassSolid = 1;  // render_common.glsl
constexpr float kNoFluid = 1e30f;                // NO_FLUID there
constexpr int kTile = 8;                         // surface texels on a side of a tile: TILE there
constexpr int kTilesHoldingFluid = 0, kTilesNearFluid = 1;  // surface_tiles.glsl's lists
constexpr GLuint kSplatGroup = 64, kTileMaskGroup = 8;      // surface_splat.comp's, tile_mask.comp's local sizes

// A compute pass's writes, read by the next as textures, images or dispatch arguments.
void pass_done() {
  glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT |
                  GL_COMMAND_BARRIER_BIT | GL_FRAMEBUFFER_BARRIER_BIT);
}

void clear(GLuint texture, GLenum format, GLenum type, const void* value = nullptr) {  // nullptr: zero
  glClearTexImage(texture, 0, format, type, value);
}

// A separable pass's direction (uniform location 0 of the smoothing shaders): x for axis 0, y for 1.
void along_axis(int axis) { glUniform2i(0, axis == 0, axis == 1); }

}  // namespace

// The Frame uniform block of render_common.glsl (std140).
struct Renderer::FrameUniforms {
  glm::mat4 view, proj, model;
  glm::vec4 light_view, domain_min, domain_max, world_up;
  glm::vec2 viewport;
  float radius;
  int32_t count, style, pass;
  float colour_scale, rho0;
  int32_t white_capacity;
};

Style parse_style(const std::string& name) {
  for (Style s : kStyles)
    if (name == style_name(s)) return s;
  throw InputError("--style must be fluid, particles, density, speed or normals, not '" + name + "'");
}

const char* style_name(Style style) {
  switch (style) {
    case Style::Fluid: return "fluid";
    case Style::Particles: return "particles";
    case Style::Density: return "density";
    case Style::Speed: return "speed";
    case Style::Normals: return "normals";
  }
  return "?";
}

Renderer::Renderer(const View& view)
    : view_(view),
      image_size_(view.width, view.height),
      surface_size_((image_size_ + view.surface_divisor - 1) / view.surface_divisor),
      image_{view.width, view.height, std::vector<uint8_t>(size_t(view.width) * view.height * 3)} {
  if (view.surface_divisor != 1 && view.surface_divisor != 2)
    throw InputError("the fluid surface's resolution divisor must be 1 or 2, not " + std::to_string(view.surface_divisor));
  const int w = view.width, h = view.height;
  vao_ = gl::make_vertex_array();
  began_ = gl::make_timestamp_query();
  drawn_ = gl::make_timestamp_query();
  glEnable(GL_PROGRAM_POINT_SIZE);  // sphere.vert sizes each particle's sprite
  frame_ubo_ = gl::make_buffer(sizeof(FrameUniforms));
  sphere_ = gl::make_program("sphere.vert", "sphere.frag");
  box_ = gl::make_program("box.vert", "box.frag");
  mesh_ = gl::make_program("mesh.vert", "box.frag");
  scene_colour_ = gl::make_texture(GL_RGBA8, w, h);
  scene_depth_ = gl::make_texture(GL_DEPTH_COMPONENT32F, w, h);
  scene_fb_ = gl::make_framebuffer({scene_colour_}, scene_depth_);
  output_colour_ = gl::make_texture(GL_RGBA8, w, h);
  output_depth_ = gl::make_texture(GL_DEPTH_COMPONENT32F, w, h);
  output_fb_ = gl::make_framebuffer({output_colour_}, output_depth_);
  if (surface_style()) {
    splat_ = gl::make_compute_program("surface_splat.comp");
    tile_mask_ = gl::make_compute_program("tile_mask.comp");
    fill_pits_ = gl::make_compute_program("fill_pits.comp");
    smooth_ = gl::make_compute_program("smooth_depth.comp");
    smooth_thickness_ = gl::make_compute_program("smooth_thickness.comp");
    normals_ = gl::make_compute_program("surface_normals.comp");
    smooth_normals_ = gl::make_compute_program("smooth_normals.comp");
    fluid_ = gl::make_compute_program("fluid_shade.comp");
    white_water_ = gl::make_program("white_water.vert", "white_water.frag");
    // The smoothed surface holds (linear eye depth, coverage 1) where there is fluid and 0
    // elsewhere, so that the shading's bilinear read at full size, r/g, blends only depths
    // of fluid and g says how much of the pixel the fluid covers. (The splat's depth,
    // before smoothing, is NO_FLUID where no sphere was drawn.)
    const int sw = surface_size_.x, sh = surface_size_.y;
    splat_depth_ = gl::make_texture(GL_R32UI, sw, sh);
    splat_depth_view_ = gl::make_texture_view(splat_depth_, GL_R32F);
    chord_sum_ = gl::make_texture(GL_R32UI, sw, sh);
    filled_depth_ = gl::make_texture(GL_R32F, sw, sh);
    for (auto& t : fluid_depth_) t = gl::make_texture(GL_RG32F, sw, sh, GL_LINEAR);
    thickness_ = gl::make_texture(GL_R32F, sw, sh, GL_LINEAR);
    thickness_blur_ = gl::make_texture(GL_R32F, sw, sh);
    for (auto& t : normal_) t = gl::make_texture(GL_RGBA16F, sw, sh, GL_LINEAR);
    tiles_ = (surface_size_ + kTile - 1) / kTile;
    // The dispatches (4 words each), then both lists interleaved: a tile's place in each.
    tile_lists_ = gl::make_buffer(GLsizeiptr(sizeof(GLuint)) * (8 + 2 * tiles_.x * tiles_.y));
  }
  for (const Obstacle& o : view.obstacles) {
    if (o.kind == Obstacle::Kind::Sphere) obstacle_spheres_.push_back(gl::make_buffer(GLsizeiptr(frame_bytes(1))));
    if (o.kind != Obstacle::Kind::Mesh || !o.corners) continue;
    std::vector<glm::vec4> corners;  // std430 pads a vec3 array to vec4s
    for (const glm::vec3& c : *o.corners) corners.emplace_back(c, 1.0f);
    // A container is seen from inside, as the tank's walls are: its triangles turned to face
    // the fluid, so that the walls nearer the eye than the fluid are left out (box.frag).
    if (o.container)
      for (size_t t = 0; t + 2 < corners.size(); t += 3) std::swap(corners[t + 1], corners[t + 2]);
    obstacle_meshes_.push_back(gl::make_buffer(GLsizeiptr(corners.size() * sizeof(glm::vec4))));
    glNamedBufferSubData(obstacle_meshes_.back(), 0, GLsizeiptr(corners.size() * sizeof(glm::vec4)), corners.data());
  }
  upload_spheres();
}

void Renderer::upload_spheres() {
  size_t sphere = 0;
  for (const Obstacle& o : view_.obstacles)
    if (o.kind == Obstacle::Kind::Sphere)
      upload_frame(obstacle_spheres_[sphere++], {{glm::vec4(glm::vec3(o.pose.world(o.centre)), 0)}, {glm::vec4(0)}, {0.0f}, {0}});
}

void Renderer::set_poses(const Pose& tank, const std::vector<Pose>& poses) {
  bool moved = !(view_.tank == tank);
  view_.tank = tank;
  for (size_t k = 0; k < std::min(poses.size(), view_.obstacles.size()); ++k)
    if (!(view_.obstacles[k].pose == poses[k])) view_.obstacles[k].pose = poses[k], moved = true;
  if (!moved) return;
  upload_spheres();
  tank_drawn_ = false;  // drawn again where they stand now
}

void Renderer::set_camera(const Camera& camera) {
  view_.camera = camera;
  tank_drawn_ = false;  // the tank's image is the camera's
}

CameraAxes camera_axes(const Camera& c) {
  const glm::dvec3 forward = glm::normalize(c.target - c.eye);
  const glm::dvec3 hint = std::abs(forward.y) > 0.999 ? glm::dvec3(0, 0, -1) : glm::dvec3(0, 1, 0);
  const glm::dvec3 right = glm::normalize(glm::cross(forward, hint));
  return {right, glm::cross(right, forward), forward};
}

Renderer::FrameUniforms Renderer::uniforms(uint32_t count, int pass, glm::ivec2 viewport, uint32_t white) const {
  const Camera& c = view_.camera;
  glm::vec3 eye(c.eye), target(c.target);
  glm::vec3 lo(view_.domain.min), hi(view_.domain.max);
  // Near and far planes enclose the domain as seen from the eye.
  float far = 0;
  for (int k = 0; k < 8; ++k)
    far = std::max(far, glm::length(glm::vec3(view_.tank.world(view_.domain.corner(k))) - eye));
  far = 1.5f * far + 1.0f;
  FrameUniforms u{};
  // Everything is drawn in the tank's frame (the solver's), seen from where the tank stands.
  const glm::mat4 camera = glm::lookAt(eye, target, glm::vec3(camera_axes(c).up));
  glm::mat4 tank(glm::mat3(view_.tank.rotation));
  tank[3] = glm::vec4(glm::vec3(view_.tank.translation), 1.0f);
  u.view = camera * tank;
  u.model = glm::mat4(1.0f);
  u.proj = glm::perspective(glm::radians(float(c.fov_degrees)), float(view_.width) / float(view_.height),
                            std::max(far * 1e-4f, 1e-3f), far);
  u.light_view = glm::vec4(glm::normalize(glm::mat3(camera) * glm::normalize(glm::vec3(0.3f, 1.0f, 0.5f))), 0.0f);
  u.world_up = glm::vec4(glm::vec3(glm::transpose(view_.tank.rotation) * glm::dvec3(0, 1, 0)), 0.0f);
  u.domain_min = glm::vec4(lo, 0.0f);
  u.domain_max = glm::vec4(hi, 0.0f);
  u.viewport = glm::vec2(viewport);
  u.radius = float(view_.particle_radius);
  u.count = int32_t(count);
  u.style = int32_t(view_.style);
  u.pass = pass;
  u.colour_scale = float(view_.style == Style::Density ? kDensityScale : view_.speed_scale);
  u.rho0 = float(view_.rest_density);
  u.white_capacity = int32_t(white);
  return u;
}

void Renderer::upload(const FrameUniforms& u) {
  glNamedBufferSubData(frame_ubo_, 0, sizeof u, &u);
  glBindBufferBase(GL_UNIFORM_BUFFER, 0, frame_ubo_);
}

// Particles as point sprites (sphere.vert); obstacle spheres are quads, drawn by
// draw_tank_and_obstacles.
void Renderer::draw_spheres(uint32_t count, int pass, glm::ivec2 viewport) {
  if (count == 0) return;
  upload(uniforms(count, pass, viewport));
  glUseProgram(sphere_);
  glDrawArrays(GL_POINTS, 0, GLsizei(count));
}

const Image& Renderer::render(GLuint buffer, uint32_t count, uint32_t white_capacity) {
  const int w = view_.width, h = view_.height;
  glQueryCounter(began_, GL_TIMESTAMP);
  glBindVertexArray(vao_);
  glViewport(0, 0, w, h);
  // The camera, the tank and the obstacles stand still: they are drawn once, and each frame
  // starts from a copy of their image, a fraction of their drawing's cost (docs/performance.md),
  // and, for the sphere styles, which test against it, of their depth.
  const bool fluid = surface_style();
  if (!tank_drawn_) draw_tank_and_obstacles();
  tank_drawn_ = true;
  copy_image(scene_colour_, output_colour_);
  if (!fluid) copy_image(scene_depth_, output_depth_);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, buffer);
  if (fluid) {
    fluid_surface(count);
    if (white_capacity > 0 && draws_white_water(view_.style)) white_water(buffer, count, white_capacity);
  } else {
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glBindFramebuffer(GL_FRAMEBUFFER, output_fb_);
    draw_spheres(count, kPassShaded, image_size_);
    glDisable(GL_DEPTH_TEST);
  }
  glQueryCounter(drawn_, GL_TIMESTAMP);

  glBindFramebuffer(GL_READ_FRAMEBUFFER, output_fb_);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  uint8_t* rgb = image_.rgb.data();
  glReadPixels(0, 0, w, h, GL_RGB, GL_UNSIGNED_BYTE, rgb);
  const size_t row = size_t(w) * 3;
  for (int y = 0; y < h / 2; ++y)  // GL's rows run from the bottom
    std::swap_ranges(rgb + y * row, rgb + (y + 1) * row, rgb + (h - 1 - y) * row);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  GLuint64 began = 0, drawn = 0;  // ready: the read-back waited for the drawing
  glGetQueryObjectui64v(began_, GL_QUERY_RESULT, &began);
  glGetQueryObjectui64v(drawn_, GL_QUERY_RESULT, &drawn);
  last_gpu_seconds_ = 1e-9 * double(drawn - began);
  return image_;
}

void Renderer::copy_image(GLuint from, GLuint to) const {
  glCopyImageSubData(from, GL_TEXTURE_2D, 0, 0, 0, 0, to, GL_TEXTURE_2D, 0, 0, 0, 0, image_size_.x, image_size_.y, 1);
}

void Renderer::draw_tank_and_obstacles() {
  // The tank: sky, floor and the walls behind the fluid.
  // The normals style shows the fluid only: the tank is drawn into the depth alone, so that
  // it still hides the fluid behind obstacles.
  glBindFramebuffer(GL_FRAMEBUFFER, scene_fb_);
  const bool normals = view_.style == Style::Normals;
  const float sky[4] = {0.80f, 0.85f, 0.90f, 1.0f}, black[4] = {0, 0, 0, 1}, far_depth = 1.0f;
  glClearNamedFramebufferfv(scene_fb_, GL_COLOR, 0, normals ? black : sky);
  if (normals) glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  glClearNamedFramebufferfv(scene_fb_, GL_DEPTH, 0, &far_depth);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glUseProgram(box_);
  upload(uniforms(0, kPassShaded, image_size_));
  glDrawArrays(GL_TRIANGLES, 0, 36);

  size_t sphere = 0, mesh = 0;
  for (const Obstacle& o : view_.obstacles) {
    FrameUniforms u = uniforms(1, o.container ? kPassShaded : kPassSolid, image_size_);  // a container: as the tank
    u.model = glm::mat4(glm::mat3(o.pose.rotation));
    u.model[3] = glm::vec4(glm::vec3(o.pose.translation), 1.0f);
    if (o.kind == Obstacle::Kind::Mesh && o.corners) {
      upload(u);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, obstacle_meshes_[mesh++]);
      glUseProgram(mesh_);
      glDrawArrays(GL_TRIANGLES, 0, GLsizei(o.corners->size()));
    } else if (o.kind == Obstacle::Kind::Box) {
      u.domain_min = glm::vec4(glm::vec3(o.min), 0.0f);
      u.domain_max = glm::vec4(glm::vec3(o.max), 0.0f);
      upload(u);
      glUseProgram(box_);
      glDrawArrays(GL_TRIANGLES, 0, 36);
    } else if (o.kind == Obstacle::Kind::Sphere) {
      u.radius = float(o.radius);
      upload(u);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, obstacle_spheres_[sphere++]);
      glUseProgram(sphere_);
      glDrawArrays(GL_TRIANGLES, 0, 6);  // a quad: it may pass the largest point size
    }
  }
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
}

void Renderer::fluid_surface(uint32_t count) {
  const glm::vec2 image_per_texel = glm::vec2(image_size_) / glm::vec2(surface_size_);
  // 1. The splat: per surface texel, the nearest sphere's linear eye depth and every
  //    sphere's chord summed (surface_splat.comp), behind the tank's depth.
  const GLuint no_fluid = glm::floatBitsToUint(kNoFluid);
  clear(splat_depth_, GL_RED_INTEGER, GL_UNSIGNED_INT, &no_fluid);
  clear(chord_sum_, GL_RED_INTEGER, GL_UNSIGNED_INT);
  upload(uniforms(count, kPassShaded, surface_size_));
  glUseProgram(splat_);
  glUniform2f(2, image_per_texel.x, image_per_texel.y);
  glBindImageTexture(0, splat_depth_, 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
  glBindImageTexture(1, chord_sum_, 0, GL_FALSE, 0, GL_READ_WRITE, GL_R32UI);
  glBindTextureUnit(3, scene_depth_);
  glDispatchCompute((count + kSplatGroup - 1) / kSplatGroup, 1, 1);
  pass_done();

  // 2. The lists of tiles that hold fluid and of those near it (tile_mask.comp), on which
  //    every later pass runs (surface_tiles.glsl).
  const GLuint no_tiles[8] = {0, 1, 1, 0, 0, 1, 1, 0};
  glNamedBufferSubData(tile_lists_, 0, sizeof no_tiles, no_tiles);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, tile_lists_);
  glBindBuffer(GL_DISPATCH_INDIRECT_BUFFER, tile_lists_);
  glUseProgram(tile_mask_);
  glBindTextureUnit(0, splat_depth_view_);
  glDispatchCompute((GLuint(tiles_.x) + kTileMaskGroup - 1) / kTileMaskGroup,
                    (GLuint(tiles_.y) + kTileMaskGroup - 1) / kTileMaskGroup, 1);
  pass_done();

  // 3. The depth smoothed, then 4. the thickness blurred and the surface's normals. Every
  //    target is cleared first: texels outside the tiles must read 0 (no fluid), also for
  //    the shading's bilinear reads.
  smooth_depth();
  smooth_thickness();
  surface_normals();

  // 5. Shading over the copy of the tank, at the image's size, on the tiles near the fluid.
  upload(uniforms(count, kPassShaded, image_size_));
  glUseProgram(fluid_);
  glUniform2f(2, image_per_texel.x, image_per_texel.y);
  glBindImageTexture(0, output_colour_, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA8);
  glBindTextureUnit(0, scene_colour_);
  glBindTextureUnit(1, fluid_depth_[0]);
  glBindTextureUnit(2, thickness_);
  glBindTextureUnit(3, scene_depth_);
  glBindTextureUnit(5, normal_[0]);
  run_tiles(kTilesNearFluid);
}

// 6. White water over the shaded fluid, behind the tank's depth (white_water.vert, .frag).
void Renderer::white_water(GLuint buffer, uint32_t count, uint32_t white_capacity) {
  copy_image(scene_depth_, output_depth_);
  glBindFramebuffer(GL_FRAMEBUFFER, output_fb_);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_FALSE);
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  upload(uniforms(count, kPassShaded, image_size_, white_capacity));
  glUseProgram(white_water_);
  glBindTextureUnit(1, fluid_depth_[0]);
  glBindBuffer(GL_DRAW_INDIRECT_BUFFER, buffer);  // the frame's header counts the living (white_header)
  glDrawArraysIndirect(GL_POINTS, reinterpret_cast<const void*>(frame_offsets(count, white_capacity).white_count));
  glBindBuffer(GL_DRAW_INDIRECT_BUFFER, 0);
  glDisable(GL_BLEND);
  glDepthMask(GL_TRUE);
  glDisable(GL_DEPTH_TEST);
}

void Renderer::run_tiles(int kind) {
  glUniform1i(1, kind);
  glDispatchComputeIndirect(GLintptr(kind) * 4 * GLintptr(sizeof(GLuint)));
  pass_done();
}

// 3. The splat's pits filled into filled_depth_ (fill_pits.comp), then a separable bilateral
//    filter, x into fluid_depth_[1], y into fluid_depth_[0] (smooth_depth.comp).
void Renderer::smooth_depth() {
  clear(filled_depth_, GL_RED, GL_FLOAT);
  glUseProgram(fill_pits_);
  glBindTextureUnit(0, splat_depth_view_);
  glBindImageTexture(0, filled_depth_, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
  run_tiles(kTilesHoldingFluid);
  glUseProgram(smooth_);
  const GLuint from[2] = {filled_depth_, fluid_depth_[1]}, to[2] = {fluid_depth_[1], fluid_depth_[0]};
  for (int axis = 0; axis < 2; ++axis) {
    clear(to[axis], GL_RG, GL_FLOAT);
    glBindTextureUnit(0, from[axis]);
    glBindImageTexture(0, to[axis], 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RG32F);
    along_axis(axis);
    run_tiles(kTilesHoldingFluid);
  }
}

// 4a. The thickness blurred, x from the chord sums into thickness_blur_, then y into
//     thickness_ (smooth_thickness.comp).
void Renderer::smooth_thickness() {
  glUseProgram(smooth_thickness_);
  glBindTextureUnit(0, chord_sum_);
  glBindTextureUnit(1, fluid_depth_[0]);
  glBindTextureUnit(6, thickness_blur_);
  const GLuint to[2] = {thickness_blur_, thickness_};
  for (int axis = 0; axis < 2; ++axis) {
    clear(to[axis], GL_RED, GL_FLOAT);
    glBindImageTexture(0, to[axis], 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
    along_axis(axis);
    run_tiles(kTilesHoldingFluid);
  }
}

// 4b. The surface's normals from the smoothed depth into normal_[0], then smoothed along
//     the surface, x into normal_[1] and y back into normal_[0] (smooth_normals.comp).
void Renderer::surface_normals() {
  for (const gl::Object& t : normal_) clear(t, GL_RGBA, GL_FLOAT);
  glUseProgram(normals_);
  glBindTextureUnit(0, fluid_depth_[0]);
  glBindImageTexture(0, normal_[0], 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA16F);
  run_tiles(kTilesHoldingFluid);
  glUseProgram(smooth_normals_);
  for (int axis = 0; axis < 2; ++axis) {
    glBindTextureUnit(0, normal_[axis]);
    glBindImageTexture(0, normal_[1 - axis], 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA16F);
    along_axis(axis);
    run_tiles(kTilesHoldingFluid);
  }
}

}  // namespace pbflow::capture
