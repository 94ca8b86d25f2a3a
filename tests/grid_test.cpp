// Neighbour search: the GPU counting sort finds exactly the pairs a brute-force search finds.
#include <algorithm>
#include <numeric>
#include <random>
#include <set>

#include "gpu/gpu_grid.hpp"
#include "sim/kernels.hpp"
#include "sim/reference_solver.hpp"
#include "support.hpp"
#include "vk/commands.hpp"

namespace pbflow {
namespace {

struct Sorted {
  std::vector<uint32_t> cell_start, id;
  std::vector<glm::vec4> x;
};

Sorted gpu_sort(const Derived& d, const std::vector<glm::vec4>& x) {
  vk::Context& ctx = test::gpu();
  SimConstants sim = d.to_gpu(uint32_t(x.size()));
  GpuGrid grid(ctx, plan_buffers(d, x.size()).grid);
  const size_t n = x.size();
  vk::Buffer x_in(ctx, n * 16), payload_in(ctx, n * 16), id_in(ctx, n * 4);
  vk::Buffer x_out(ctx, n * 16), payload_out(ctx, n * 16), id_out(ctx, n * 4);
  std::vector<uint32_t> ids(n);
  std::iota(ids.begin(), ids.end(), 0u);
  x_in.upload(std::span<const glm::vec4>(x));
  payload_in.upload(std::span<const glm::vec4>(x));
  id_in.upload(std::span<const uint32_t>(ids));
  vk::CommandList cmd(ctx);
  cmd.begin();
  grid.build(cmd, sim, {&x_in, &payload_in, &id_in}, {&x_out, &payload_out, &id_out});
  cmd.submit_and_wait();
  size_t cells = size_t(d.grid.x) * d.grid.y * d.grid.z;
  return {grid.cell_start().download<uint32_t>(cells + 1), id_out.download<uint32_t>(n), x_out.download<glm::vec4>(n)};
}

// Checks the sort, then that the 27-cell search finds every pair within h and no other.
void expect_exact_neighbours(const Derived& d, const std::vector<glm::vec4>& x) {
  Sorted s = gpu_sort(d, x);
  const size_t n = x.size();
  const glm::ivec3 g = d.grid;
  ASSERT_EQ(s.cell_start.back(), n);
  ASSERT_TRUE(std::is_sorted(s.cell_start.begin(), s.cell_start.end()));
  std::vector<uint32_t> seen = s.id;
  std::sort(seen.begin(), seen.end());
  for (uint32_t k = 0; k < n; ++k) ASSERT_EQ(seen[k], k) << "ids after the sort are not a permutation";

  std::vector<glm::ivec3> cell_of(n);  // binned cell of each sorted particle
  for (int c = 0; c < g.x * g.y * g.z; ++c)
    for (uint32_t k = s.cell_start[c]; k < s.cell_start[c + 1]; ++k) {
      ASSERT_EQ(s.x[k], x[s.id[k]]) << "particle data did not travel with its id";
      glm::ivec3 cc(c % g.x, (c / g.x) % g.y, c / (g.x * g.y));
      glm::dvec3 lo = d.domain_min + d.h * glm::dvec3(cc), hi = lo + d.h, p = glm::dvec3(glm::vec3(s.x[k]));
      const double tol = 1e-5 * d.h;  // float rounding at cell borders
      for (int a = 0; a < 3; ++a) {
        if (cc[a] > 0) {
          EXPECT_GE(p[a], lo[a] - tol) << "particle binned in the wrong cell";
        }
        if (cc[a] < g[a] - 1) {
          EXPECT_LE(p[a], hi[a] + tol) << "particle binned in the wrong cell";
        }
      }
      cell_of[k] = cc;
    }

  const double h2 = d.h * d.h;
  size_t pairs = 0;
  for (uint32_t i = 0; i < n; ++i) {
    glm::dvec3 xi(glm::vec3(s.x[i]));
    std::set<uint32_t> found, brute;
    glm::ivec3 c = cell_of[i];
    for (int z = std::max(c.z - 1, 0); z <= std::min(c.z + 1, g.z - 1); ++z)
      for (int y = std::max(c.y - 1, 0); y <= std::min(c.y + 1, g.y - 1); ++y)
        for (int xx = std::max(c.x - 1, 0); xx <= std::min(c.x + 1, g.x - 1); ++xx) {
          int cell = (z * g.y + y) * g.x + xx;
          for (uint32_t j = s.cell_start[cell]; j < s.cell_start[cell + 1]; ++j) {
            glm::dvec3 dj = xi - glm::dvec3(glm::vec3(s.x[j]));
            if (glm::dot(dj, dj) < h2) found.insert(s.id[j]);
          }
        }
    for (uint32_t j = 0; j < n; ++j) {
      glm::dvec3 dj = xi - glm::dvec3(glm::vec3(s.x[j]));
      if (glm::dot(dj, dj) < h2) brute.insert(s.id[j]);
    }
    ASSERT_EQ(found, brute) << "neighbours of particle " << s.id[i];
    pairs += brute.size();
  }
  EXPECT_GT(pairs, n);  // the sets compared were not trivially empty
}

Derived box_domain(glm::dvec3 size, double spacing) {
  std::string max = "[" + std::to_string(size.x) + "," + std::to_string(size.y) + "," + std::to_string(size.z) + "]";
  Scene s = load_scene("hydrostatic", {"domain.max=" + max, "particle_spacing=" + std::to_string(spacing),
                                             "fluid_blocks=[{\"min\":[0,0,0],\"max\":" + max + "}]"});
  return derive(s);
}

class GridTest : public test::GpuTest {};

TEST_F(GridTest, RandomParticlesWithBordersAndEdges) {
  Derived d = box_domain({0.5, 0.3, 0.4}, 0.02);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<glm::vec4> x;
  for (int i = 0; i < 3000; ++i)
    x.emplace_back(glm::vec3(d.domain_min + glm::dvec3(u(rng), u(rng), u(rng)) * (d.domain_max - d.domain_min)), 0);
  // Exactly on cell borders, and on every face and corner of the domain.
  for (int i = 0; i < 300; ++i)
    x.emplace_back(glm::vec3(d.h * std::floor(u(rng) * d.grid.x), d.h * std::floor(u(rng) * d.grid.y),
                             d.h * std::floor(u(rng) * d.grid.z)),
                   0);
  for (int corner = 0; corner < 8; ++corner)
    x.emplace_back(glm::vec3(corner & 1 ? d.domain_max.x : d.domain_min.x, corner & 2 ? d.domain_max.y : d.domain_min.y,
                             corner & 4 ? d.domain_max.z : d.domain_min.z),
                   0);
  expect_exact_neighbours(d, x);
}

TEST_F(GridTest, Lattice) {
  Derived d = box_domain({0.4, 0.4, 0.4}, 0.02);
  std::vector<glm::vec4> x;
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 20; ++j)
      for (int k = 0; k < 20; ++k) x.emplace_back(glm::vec3(0.01f + 0.02f * glm::vec3(i, j, k)), 0);
  expect_exact_neighbours(d, x);
}

// The sort is the same on every run: a cell's particles keep their order of input (here the
// ids), whatever order the count's atomics took. 64 particles crowd each cell, so that the
// atomics of a cell's particles land in many orders, and the sort runs ten times.
TEST_F(GridTest, ACellsParticlesKeepTheirOrderOfInput) {
  Derived d = box_domain({0.2, 0.2, 0.2}, 0.02);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<glm::vec4> x;
  for (int i = 0; i < 64 * d.grid.x * d.grid.y * d.grid.z; ++i)
    x.emplace_back(glm::vec3(d.domain_min + glm::dvec3(u(rng), u(rng), u(rng)) * (d.domain_max - d.domain_min)), 0);
  const Sorted first = gpu_sort(d, x);
  for (size_t c = 0; c + 1 < first.cell_start.size(); ++c)
    for (uint32_t k = first.cell_start[c]; k + 1 < first.cell_start[c + 1]; ++k)
      ASSERT_LT(first.id[k], first.id[k + 1]) << "cell " << c << ": the atomics' order came through";
  for (int run = 0; run < 10; ++run) EXPECT_EQ(gpu_sort(d, x).id, first.id) << "sort " << run;
}

TEST_F(GridTest, ManyCellsScanInManyGroups) {
  // 128 x 128 x 80 cells = 1.3M, 1281 blocks: a group per block, then their sums in one
  // group, then added back (the grids of the tests above scan in one group).
  Derived d = box_domain({6.4, 6.4, 4.0}, 0.025);
  ASSERT_GT(size_t(d.grid.x) * d.grid.y * d.grid.z, size_t(1024) * 1024);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<glm::vec4> x;
  // Clustered, so that pairs exist: a dense blob plus scattered particles.
  for (int i = 0; i < 4000; ++i) x.emplace_back(glm::vec3(3.0 + 0.3 * u(rng), 3.0 + 0.3 * u(rng), 2.0 + 0.3 * u(rng)), 0);
  for (int i = 0; i < 2000; ++i) x.emplace_back(glm::vec3(6.4 * u(rng), 6.4 * u(rng), 4.0 * u(rng)), 0);
  expect_exact_neighbours(d, x);
}

TEST(ReferenceGrid, DensityMatchesBruteForce) {
  Scene scene = load_scene("dam_break", {"particle_spacing=0.04"});
  Derived d = derive(scene);
  ParticleState st = test::jittered_state(scene);
  ReferenceSolver ref(d, st.x);
  ref.build_grid(ref.state.x);
  ref.density();
  for (size_t i = 0; i < st.x.size(); i += 7) {
    double rho = 0;
    for (size_t j = 0; j < st.x.size(); ++j)
      for (int k = 0; k < kImages; ++k) {
        const Mirrors mirrors = mirrors_near(d, st.x[i]);
        if ((k & mirrors.axes) != k) continue;
        glm::dvec3 dd = st.x[i] - mirrors.of(k, st.x[j]);
        rho += d.mass * kernels::poly6(glm::dot(dd, dd), d.h);
      }
    ASSERT_NEAR(ref.state.rho[i], rho, 1e-12 * rho) << "particle " << i;
  }
}

}  // namespace
}  // namespace pbflow
