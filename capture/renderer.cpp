#include "capture/renderer.hpp"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>

#include "capture/gl_context.hpp"
#include "capture/particle_transfer.hpp"

namespace pbflow::capture {

namespace {

constexpr int kPassShaded = 0, kPassSurface = 1, kPassSolid = 2;  // render_common.glsl
constexpr float kNoFluid = 1e30f;                                   // NO_FLUID there
constexpr int kSmoothingRounds = 1;  // bilateral x then y, once (smooth_depth.frag says why)
constexpr int kTile = 8;             // surface texels on a side of a tile: TILE in render_common.glsl
constexpr int kTilesHoldingFluid = 0, kTilesNearFluid = 1;  // tile_mask.frag's channels

}  // namespace

// The Frame uniform block of render_common.glsl (std140).
struct Renderer::FrameUniforms {
  glm::mat4 view, proj;
  glm::vec4 light_view, domain_min, domain_max;
  glm::vec2 viewport;
  float radius;
  int32_t count, style, pass;
  float colour_scale, rho0;
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
  timer_ = gl::make_time_query();
  glEnable(GL_PROGRAM_POINT_SIZE);  // sphere.vert sizes each particle's sprite
  frame_ubo_ = gl::make_buffer(sizeof(FrameUniforms));
  sphere_ = gl::make_program("sphere.vert", "sphere.frag");
  sphere_surface_ = gl::make_program("sphere.vert", "sphere_surface.frag");
  box_ = gl::make_program("box.vert", "box.frag");
  scene_colour_ = gl::make_texture(GL_RGBA8, w, h);
  scene_depth_ = gl::make_texture(GL_DEPTH_COMPONENT32F, w, h);
  scene_fb_ = gl::make_framebuffer({scene_colour_}, scene_depth_);
  output_colour_ = gl::make_texture(GL_RGBA8, w, h);
  output_depth_ = gl::make_texture(GL_DEPTH_COMPONENT32F, w, h);
  output_fb_ = gl::make_framebuffer({output_colour_}, output_depth_);
  if (surface_style()) {
    tile_mask_ = gl::make_program("fullscreen.vert", "tile_mask.frag");
    smooth_ = gl::make_program("surface_tiles.vert", "smooth_depth.frag");
    smooth_thickness_ = gl::make_program("surface_tiles.vert", "smooth_thickness.frag");
    normals_ = gl::make_program("surface_tiles.vert", "surface_normals.frag");
    smooth_normals_ = gl::make_program("surface_tiles.vert", "smooth_normals.frag");
    fluid_ = gl::make_program("surface_tiles.vert", "fluid_shade.frag");
    // The smoothed surface holds (linear eye depth, coverage 1) where there is fluid and 0
    // elsewhere, so that the shading's bilinear read at full size, r/g, blends only depths
    // of fluid and g says how much of the pixel the fluid covers. (The surface pass's raw
    // depth, before smoothing, is NO_FLUID where no sphere was drawn.)
    const int sw = surface_size_.x, sh = surface_size_.y;
    for (auto& t : fluid_depth_) t = gl::make_texture(GL_RG32F, sw, sh, GL_LINEAR);
    tiles_ = (surface_size_ + kTile - 1) / kTile;
    tile_marks_ = gl::make_texture(GL_RG8, tiles_.x, tiles_.y);
    tile_marks_fb_ = gl::make_framebuffer({tile_marks_}, 0);
    thickness_ = gl::make_texture(GL_R32F, sw, sh, GL_LINEAR);
    // The tank's depth at the surface's size: fluid behind an obstacle stays hidden.
    surface_zbuffer_ = gl::make_texture(GL_DEPTH_COMPONENT32F, sw, sh);
    surface_fb_ = gl::make_framebuffer({fluid_depth_[0], thickness_}, surface_zbuffer_);
    smooth_fb_[0] = gl::make_framebuffer({fluid_depth_[1]}, 0);
    smooth_fb_[1] = gl::make_framebuffer({fluid_depth_[0]}, 0);
    thickness_blur_ = gl::make_texture(GL_R32F, sw, sh, GL_LINEAR);
    thickness_fb_[0] = gl::make_framebuffer({thickness_blur_}, 0);
    thickness_fb_[1] = gl::make_framebuffer({thickness_}, 0);
    for (int k = 0; k < 2; ++k) {
      normal_[k] = gl::make_texture(GL_RGBA16F, sw, sh, GL_LINEAR);
      normal_fb_[k] = gl::make_framebuffer({normal_[k]}, 0);
    }
  }
  for (const Obstacle& o : view.obstacles) {
    if (o.kind != Obstacle::Kind::Sphere) continue;
    obstacle_spheres_.push_back(gl::make_buffer(GLsizeiptr(frame_bytes(1))));
    upload_frame(obstacle_spheres_.back(), {{glm::vec4(glm::vec3(o.centre), 0)}, {glm::vec4(0)}, {0.0f}, {0}});
  }
}

Renderer::FrameUniforms Renderer::uniforms(uint32_t count, int pass, glm::ivec2 viewport) const {
  const Camera& c = view_.camera;
  glm::vec3 eye(c.eye), target(c.target);
  glm::vec3 lo(view_.domain.min), hi(view_.domain.max);
  // Near and far planes enclose the domain as seen from the eye.
  float far = 0;
  for (int k = 0; k < 8; ++k) far = std::max(far, glm::length(glm::vec3(view_.domain.corner(k)) - eye));
  far = 1.5f * far + 1.0f;
  FrameUniforms u{};
  // Up is +y, unless the camera looks (nearly) along it: then the image's up is -z, as on a map.
  glm::vec3 forward = glm::normalize(target - eye);
  glm::vec3 up = std::abs(forward.y) > 0.999f ? glm::vec3(0, 0, -1) : glm::vec3(0, 1, 0);
  u.view = glm::lookAt(eye, target, up);
  u.proj = glm::perspective(glm::radians(float(c.fov_degrees)), float(view_.width) / float(view_.height),
                            std::max(far * 1e-4f, 1e-3f), far);
  u.light_view = glm::vec4(glm::normalize(glm::mat3(u.view) * glm::normalize(glm::vec3(0.3f, 1.0f, 0.5f))), 0.0f);
  u.domain_min = glm::vec4(lo, 0.0f);
  u.domain_max = glm::vec4(hi, 0.0f);
  u.viewport = glm::vec2(viewport);
  u.radius = float(view_.particle_radius);
  u.count = int32_t(count);
  u.style = int32_t(view_.style);
  u.pass = pass;
  u.colour_scale = float(view_.style == Style::Density ? kDensityScale : view_.speed_scale);
  u.rho0 = float(view_.rest_density);
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
  glUseProgram(pass == kPassSurface ? sphere_surface_ : sphere_);
  glDrawArrays(GL_POINTS, 0, GLsizei(count));
}

const Image& Renderer::render(GLuint buffer, uint32_t count) {
  const int w = view_.width, h = view_.height;
  glBeginQuery(GL_TIME_ELAPSED, timer_);
  glBindVertexArray(vao_);
  glViewport(0, 0, w, h);
  // The camera, the tank and the obstacles stand still: they are drawn once (4-8 ms of a
  // 720p frame on llvmpipe), and each frame starts from a copy of their image (0.35 ms)
  // and, for the sphere styles, which test against it, of their depth.
  const bool fluid = surface_style();
  if (!tank_drawn_) draw_tank_and_obstacles();
  tank_drawn_ = true;
  copy_image(scene_colour_, output_colour_);
  if (!fluid) copy_image(scene_depth_, output_depth_);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, buffer);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  if (fluid) {
    fluid_surface(count);
  } else {
    glBindFramebuffer(GL_FRAMEBUFFER, output_fb_);
    draw_spheres(count, kPassShaded, image_size_);
  }
  glDisable(GL_DEPTH_TEST);
  glEndQuery(GL_TIME_ELAPSED);

  glBindFramebuffer(GL_READ_FRAMEBUFFER, output_fb_);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  uint8_t* rgb = image_.rgb.data();
  glReadPixels(0, 0, w, h, GL_RGB, GL_UNSIGNED_BYTE, rgb);
  const size_t row = size_t(w) * 3;
  for (int y = 0; y < h / 2; ++y)  // GL's rows run from the bottom
    std::swap_ranges(rgb + y * row, rgb + (y + 1) * row, rgb + (h - 1 - y) * row);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  GLuint64 ns = 0;  // ready: the read-back waited for the drawing
  glGetQueryObjectui64v(timer_, GL_QUERY_RESULT, &ns);
  last_gpu_seconds_ = 1e-9 * double(ns);
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

  size_t sphere = 0;
  for (const Obstacle& o : view_.obstacles) {
    FrameUniforms u = uniforms(1, kPassSolid, image_size_);
    if (o.kind == Obstacle::Kind::Box) {
      u.domain_min = glm::vec4(glm::vec3(o.min), 0.0f);
      u.domain_max = glm::vec4(glm::vec3(o.max), 0.0f);
      upload(u);
      glUseProgram(box_);
      glDrawArrays(GL_TRIANGLES, 0, 36);
    } else {
      u.radius = float(o.radius);
      upload(u);
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, obstacle_spheres_[sphere++]);
      glUseProgram(sphere_);
      glDrawArrays(GL_TRIANGLES, 0, 6);  // a quad: it may pass the largest point size
    }
  }
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  // The fluid's surface passes test against the tank's depth at their own size; they
  // never write it.
  if (surface_style())
    glBlitNamedFramebuffer(scene_fb_, surface_fb_, 0, 0, image_size_.x, image_size_.y, 0, 0, surface_size_.x,
                           surface_size_.y, GL_DEPTH_BUFFER_BIT, GL_NEAREST);
}

void Renderer::fluid_surface(uint32_t count) {
  const glm::ivec2 size = surface_size_;
  glViewport(0, 0, size.x, size.y);
  // 1. Nearest sphere depth per pixel (linear eye depth) and every sphere's chord summed,
  //    in one draw: min and sum blending. The tank's depth, brought to the surface's size
  //    when the tank was drawn, hides the fluid behind it; fluid does not hide fluid (no
  //    depth writes).
  const float no_fluid[4] = {kNoFluid, 0, 0, 0}, zero[4] = {0, 0, 0, 0};
  glClearNamedFramebufferfv(surface_fb_, GL_COLOR, 0, no_fluid);
  glClearNamedFramebufferfv(surface_fb_, GL_COLOR, 1, zero);
  glBindFramebuffer(GL_FRAMEBUFFER, surface_fb_);
  glDepthMask(GL_FALSE);
  glEnable(GL_BLEND);
  glBlendFunc(GL_ONE, GL_ONE);
  glBlendEquationi(0, GL_MIN);
  glBlendEquationi(1, GL_FUNC_ADD);
  draw_spheres(count, kPassSurface, size);
  glBlendEquation(GL_FUNC_ADD);
  glDisable(GL_BLEND);
  glDepthMask(GL_TRUE);
  glDisable(GL_DEPTH_TEST);

  // 2. The tiles that hold fluid and those near it (tile_mask.frag), where the smoothing
  //    and the shading run (surface_tiles.vert).
  glViewport(0, 0, tiles_.x, tiles_.y);
  glBindFramebuffer(GL_FRAMEBUFFER, tile_marks_fb_);
  glUseProgram(tile_mask_);
  glBindTextureUnit(0, fluid_depth_[0]);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glBindTextureUnit(4, tile_marks_);

  // 3. Smoothing, ping-ponging between the two depth textures; ends in fluid_depth_[0].
  //    Away from the fluid the smoothed surface reads 0: each target is cleared before
  //    its first round (fluid_depth_[0] once the first round has read the splat), and
  //    every round writes the same tiles.
  glViewport(0, 0, size.x, size.y);
  upload(uniforms(count, kPassShaded, size));
  glUseProgram(smooth_);
  for (int round = 0; round < kSmoothingRounds; ++round)
    for (int axis = 0; axis < 2; ++axis) {
      if (round == 0) glClearNamedFramebufferfv(smooth_fb_[axis], GL_COLOR, 0, zero);
      glBindFramebuffer(GL_FRAMEBUFFER, smooth_fb_[axis]);
      glBindTextureUnit(0, fluid_depth_[axis]);
      glUniform2i(0, axis == 0 ? 1 : 0, axis == 0 ? 0 : 1);
      draw_tiles(kTilesHoldingFluid, glm::vec2(1.0f));
    }

  smooth_thickness();
  surface_normals();

  // 5. Shading over the copy of the tank, at the image's size, on the tiles near the fluid.
  glViewport(0, 0, image_size_.x, image_size_.y);
  upload(uniforms(count, kPassShaded, image_size_));
  glBindFramebuffer(GL_FRAMEBUFFER, output_fb_);
  glUseProgram(fluid_);
  glBindTextureUnit(0, scene_colour_);
  glBindTextureUnit(1, fluid_depth_[0]);
  glBindTextureUnit(2, thickness_);
  glBindTextureUnit(3, scene_depth_);
  glBindTextureUnit(5, normal_[0]);
  draw_tiles(kTilesNearFluid, glm::vec2(image_size_) / glm::vec2(size));
}

// 4a. The thickness blurred, x into thickness_blur_ then y back into thickness_
//     (smooth_thickness.frag). The blur target is cleared first: its texels outside the
//     tiles drawn must read 0 for the y pass.
void Renderer::smooth_thickness() {
  const float zero[4] = {0, 0, 0, 0};
  glClearNamedFramebufferfv(thickness_fb_[0], GL_COLOR, 0, zero);
  glUseProgram(smooth_thickness_);
  glBindTextureUnit(1, fluid_depth_[0]);
  const GLuint from[2] = {thickness_, thickness_blur_};
  for (int axis = 0; axis < 2; ++axis) {
    glBindFramebuffer(GL_FRAMEBUFFER, thickness_fb_[axis]);
    glBindTextureUnit(0, from[axis]);
    glUniform2i(0, axis == 0 ? 1 : 0, axis == 0 ? 0 : 1);
    draw_tiles(kTilesHoldingFluid, glm::vec2(1.0f));
  }
}

// 4b. The surface's normals from the smoothed depth, then smoothed along the surface, x then
//    y (smooth_normals.frag); ends in normal_[0]. Both targets are cleared first: texels
//    without fluid must read 0 for the shading's bilinear read.
void Renderer::surface_normals() {
  const float zero[4] = {0, 0, 0, 0};
  for (const gl::Object& fb : normal_fb_) glClearNamedFramebufferfv(fb, GL_COLOR, 0, zero);
  glBindFramebuffer(GL_FRAMEBUFFER, normal_fb_[0]);
  glUseProgram(normals_);
  glBindTextureUnit(0, fluid_depth_[0]);
  draw_tiles(kTilesHoldingFluid, glm::vec2(1.0f));
  glUseProgram(smooth_normals_);
  for (int axis = 0; axis < 2; ++axis) {
    glBindFramebuffer(GL_FRAMEBUFFER, normal_fb_[1 - axis]);
    glBindTextureUnit(0, normal_[axis]);
    glUniform2i(0, axis == 0 ? 1 : 0, axis == 0 ? 0 : 1);
    draw_tiles(kTilesHoldingFluid, glm::vec2(1.0f));
  }
}

// One point per tile of the surface (surface_tiles.vert) with the current program, drawn
// where tile_marks_ holds `channel`; `scale`: the viewport's pixels per surface texel.
void Renderer::draw_tiles(int channel, glm::vec2 scale) {
  glUniform1i(1, channel);
  glUniform2f(2, scale.x, scale.y);
  glDrawArrays(GL_POINTS, 0, tiles_.x * tiles_.y);
}

}  // namespace pbflow::capture
