// The C++/GLSL contract: a program's bindings and constants are read from its SPIR-V and
// the host names them, so a mismatch fails where it is made, not as a wrong result.
#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cstddef>
#include <stdexcept>
#include <vector>

#include "gpu/key_constants.hpp"
#include "scene/keys.hpp"
#include "sim/params.hpp"
#include "support.hpp"
#include "vk/buffer.hpp"
#include "vk/check.hpp"
#include "vk/commands.hpp"
#include "vk/program.hpp"
#include "vk/shader_library.hpp"
#include "vk/spirv_layout.hpp"

namespace pbflow {
namespace {

using vk::ShaderLayout;

const ShaderLayout::Binding* find(const ShaderLayout& layout, const std::string& name) {
  for (const auto& b : layout.bindings)
    if (b.name == name) return &b;
  return nullptr;
}

TEST(ShaderLayout, ANeighbourPassReadsItsSlotsTypesAndConstantsFromTheSpirv) {
  const ShaderLayout density = vk::reflect_layout(shaders::spirv("density"));
  ASSERT_EQ(density.bindings.size(), 7u);  // the obstacles' three views (solids.glsl) are one slot
  const struct {
    const char* name;
    uint32_t slot;
    VkFormat format;  // VK_FORMAT_UNDEFINED: a storage buffer
  } expected[] = {{"cell_start", 0, VK_FORMAT_R32_UINT},
                  {"x", 1, VK_FORMAT_R32G32B32A32_SFLOAT},
                  {"rho", 2, VK_FORMAT_UNDEFINED},
                  {"neighbour_count", 3, VK_FORMAT_R32_UINT},
                  {"neighbour_list", 4, VK_FORMAT_R32G32B32A32_UINT},
                  {"obstacles", 5, VK_FORMAT_UNDEFINED},
                  {"crease_records", 6, VK_FORMAT_UNDEFINED}};
  for (const auto& e : expected) {
    const auto* b = find(density, e.name);
    ASSERT_NE(b, nullptr) << e.name;
    EXPECT_EQ(b->slot, e.slot) << e.name;
    EXPECT_EQ(b->format, e.format) << e.name;
    EXPECT_EQ(b->type, e.format ? VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER) << e.name;
  }
  ASSERT_EQ(density.constants.size(), 7u);
  EXPECT_EQ(density.constants[0].name, "NEIGHBOUR_CAPACITY");
  EXPECT_EQ(density.constants[1].name, "WALK_CELLS");
  EXPECT_EQ(density.constants[2].name, "SHAPES");
  EXPECT_EQ(density.constants[3].name, "MOVING");  // the poses read through (solids.glsl)
  EXPECT_EQ(density.constants[4].name, "WALLS");  // whether the box's walls mirror
  EXPECT_EQ(density.constants[5].name, "OBSTACLE_MIRRORS");  // not in the far list readers
  EXPECT_EQ(density.constants[6].name, "OBSTACLE_COUNT");  // the loops over them unrolled
  EXPECT_EQ(density.constants[1].id, density.constants[0].id + 1);
}

TEST(ShaderLayout, AnonymousBlocksBindByTheirNameInSnakeCase) {
  const ShaderLayout scatter = vk::reflect_layout(shaders::spirv("grid_scatter"));
  for (const char* name : {"cell", "cell_start", "order", "x_in", "payload_in", "id_in", "x_out", "payload_out", "id_out"})
    EXPECT_NE(find(scatter, name), nullptr) << name;
}

// SimConstants and the GLSL block Sim are both expanded from shaders/sim_constants.h; this
// checks that the two layouts agree member by member, not only in their total size.
TEST(ShaderLayout, EveryPushConstantSitsWhereSimConstantsHasIt) {
  struct Field {
    std::string name;
    uint32_t offset;
  };
  const std::vector<Field> host = {
#define SIM_FIELD(type, name) {#name, uint32_t(offsetof(SimConstants, name))},
      SIM_CONSTANTS(SIM_FIELD)
#undef SIM_FIELD
  };
  for (const char* shader : {"predict", "density", "constraint_apply", "watch"}) {
    const ShaderLayout layout = vk::reflect_layout(shaders::spirv(shader));
    ASSERT_EQ(layout.push_members.size(), host.size()) << shader;
    for (size_t k = 0; k < host.size(); ++k) {
      EXPECT_EQ(layout.push_members[k].name, host[k].name) << shader;
      EXPECT_EQ(layout.push_members[k].offset, host[k].offset) << shader << ": " << host[k].name;
    }
  }
}

TEST(ShaderLayout, WordsThatAreNotSpirvAreRefused) {
  const std::vector<uint32_t> junk{1, 2, 3, 4, 5, 6};
  EXPECT_THROW(vk::reflect_layout(junk), vk::Error);
  std::vector<uint32_t> truncated(shaders::spirv("density").begin(), shaders::spirv("density").begin() + 40);
  truncated[5] = 0xffff0000u | (truncated[5] & 0xffff);  // an instruction longer than the words left
  EXPECT_THROW(vk::reflect_layout(truncated), vk::Error);
}

class ProgramContract : public test::GpuTest {};

// Expects `attempt` to throw a vk::Error whose message holds `naming`; `accepted` says what
// went wrong where it does not throw.
template <class Attempt>
void expect_refused(Attempt attempt, const std::string& naming, const char* accepted) {
  try {
    attempt();
    ADD_FAILURE() << accepted;
  } catch (const vk::Error& e) {
    EXPECT_NE(std::string(e.what()).find(naming), std::string::npos) << e.what();
  }
}

TEST_F(ProgramContract, AConstantTheShaderLacksOrOmitsIsRefusedByName) {
  const std::array<vk::Constant, 1> typo{{{"SPEED_LIMT", 0u}}};
  expect_refused([&] { vk::Program(test::gpu(), "watch", sizeof(SimConstants), 0, typo); }, "SPEED_LIMT",
                 "a constant the shader does not declare was accepted");
  expect_refused([&] { vk::Program(test::gpu(), "watch", sizeof(SimConstants)); }, "SPEED_LIMIT",
                 "a constant the shader declares was left unset");
}

// A constant carries its type: a float where the shader declares another type is refused, not
// reinterpreted as bits.
TEST_F(ProgramContract, AConstantOfAnotherTypeThanTheShadersIsRefused) {
  const std::array<vk::Constant, 1> as_whole{{{"SPEED_LIMIT", 10u}}};
  expect_refused([&] { vk::Program(test::gpu(), "watch", sizeof(SimConstants), 0, as_whole); },
                 "SPEED_LIMIT is set as another type", "a whole number was accepted for a float constant");
}

// The solver's keys reach a pass that declares them (SOLVER_XSPH and others in
// viscosity_vorticity.comp) without being named at the program's creation; without them offered
// its creation fails naming the first.
TEST_F(ProgramContract, TheSolversKeysReachEveryPassThatDeclaresThem) {
  const Scene scene = load_scene("dam_break", {"solver.xsph=0.125"});
  const KeyConstants keys(derive(scene));
  auto key = [&](std::string_view name) {
    for (const vk::Constant& c : keys.constants())
      if (c.name == name) return c;
    ADD_FAILURE() << name << " is not offered";
    return vk::Constant(name, false);
  };
  EXPECT_EQ(key("SOLVER_XSPH").value, std::bit_cast<uint32_t>(0.125f));
  EXPECT_EQ(key("SOLVER_XSPH").type, vk::ConstantType::Float);
  EXPECT_EQ(key("SOLVER_ITERATIONS").value, uint32_t(scene.solver.iterations));
  EXPECT_EQ(key("SOLVER_ITERATIONS").type, vk::ConstantType::Integer);
  EXPECT_EQ(key("SOLVER_LDC_CLAMP").type, vk::ConstantType::Bool);
  EXPECT_EQ(key("SHAPES").value, 0u);  // the dam break has no obstacles
  const std::array<vk::Constant, 3> own{{{"DAMPING_LIMIT", 0.3f}, {"NEIGHBOUR_CAPACITY", 64u}, {"WALK_CELLS", false}}};
  EXPECT_NO_THROW(vk::Program(test::gpu(), "viscosity_vorticity", sizeof(SimConstants), 0, own, keys.constants()));
  expect_refused([&] { vk::Program(test::gpu(), "viscosity_vorticity", sizeof(SimConstants), 0, own); },
                 "was not set", "the pass was made without the keys it reads");
}

// The push-constant block's size comes from the shader: a host struct of another size is
// refused at the program's creation, naming both sizes.
TEST_F(ProgramContract, APushStructOfAnotherSizeThanTheShadersBlockIsRefused) {
  EXPECT_EQ(vk::reflect_layout(shaders::spirv("watch")).push_bytes, sizeof(SimConstants));
  EXPECT_EQ(vk::reflect_layout(shaders::spirv("scan_add")).push_bytes, sizeof(uint32_t));
  expect_refused([&] { vk::Program(test::gpu(), "scan_add", 2 * sizeof(uint32_t), 64); },
                 "push-constant block is 4 bytes and the host's 8",
                 "a push struct of 8 bytes was accepted for a 4-byte block");
}

TEST_F(ProgramContract, BindingANameTheShaderLacksThrowsNamingIt) {
  const vk::Program scan(test::gpu(), "scan_add", sizeof(uint32_t), 64);
  vk::Buffer buffer(test::gpu(), 1024);
  vk::CommandList cmd(test::gpu());
  cmd.begin();
  cmd.set_program(scan);
  cmd.bind("data", buffer);
  expect_refused([&] { cmd.bind("sum", buffer); }, "sum",
                 "a binding the shader does not have was accepted");
  // A binding left unbound is refused at the dispatch, by name.
  expect_refused([&] { cmd.dispatch(64); }, "sums",
                 "a dispatch with an unbound binding was recorded");
  cmd.bind("sums", buffer);
  cmd.push(uint32_t(64));
  cmd.dispatch(64);
  cmd.submit_and_wait();
}

}  // namespace
}  // namespace pbflow
