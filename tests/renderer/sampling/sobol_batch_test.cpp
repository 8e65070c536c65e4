#include "renderer/sampling/sobol_batch.h"
#include "renderer/sampling/sobol_gfni.h"

#include <gtest/gtest.h>

#include <vector>

#include "tests/bit_exact_util.h"

namespace penumbra::test {
namespace {

// Takes one bounce's values from `sampler` in the order `pattern` says (1: get_1d, 2: get_2d),
// appending them to `out`.
template <class S>
void take(S& sampler, const int* pattern, int count, std::vector<float>* out) {
  for (int j = 0; j < count; ++j) {
    if (pattern[j] == 1) {
      out->push_back(sampler.get_1d());
    } else if (pattern[j] == 3) {  // get_1d_2d
      float u1;
      vec2 u2;
      sampler.get_1d_2d(&u1, &u2);
      out->push_back(u1);
      out->push_back(u2.x);
      out->push_back(u2.y);
    } else {
      const vec2 u = sampler.get_2d();
      out->push_back(u.x);
      out->push_back(u.y);
    }
  }
}

// Every implementation of the batch kernels this CPU runs -- the one scrambled_sobol_batch
// selects, the portable SIMD clones, the GFNI kernels where the CPU has them -- must give the
// values of the definitions to the bit, for any index and seeds (sizes not a multiple of any
// vector width).
struct SobolKernels {
  const char* name;
  void (*xy)(size_t, const uint32_t*, const uint32_t*, const uint32_t*, const uint32_t*, float*, float*);
  void (*z)(size_t, const uint32_t*, const uint32_t*, const uint32_t*, float*);
};
std::vector<SobolKernels> sobol_kernels_here() {
  std::vector<SobolKernels> kernels = {{"selected", scrambled_sobol_batch, scrambled_sobol_z_batch},
                                       {"portable", scrambled_sobol_batch_portable, scrambled_sobol_z_batch_portable}};
  if (sobol_gfni_available()) kernels.push_back({"gfni", scrambled_sobol_batch_gfni, scrambled_sobol_z_batch_gfni});
  return kernels;
}

TEST(SobolBatch, KernelIsTheScalarSamplerToTheBit) {
  for (const SobolKernels& kernels : sobol_kernels_here()) {
    for (size_t n : {1u, 7u, 15u, 16u, 17u, 37u, 1280u}) {
      std::vector<uint32_t> index(n), si(n), sx(n), sy(n);
      XorShift32 random{2463534242u + uint32_t(n)};
      auto next = [&random] { return random.next(); };
      for (size_t i = 0; i < n; ++i) {
        index[i] = i % 3 == 0 ? uint32_t(i) : next();
        si[i] = next();
        sx[i] = next();
        sy[i] = next();
      }
      // Entries past n are left as they were (a tail written past the end would show here).
      std::vector<float> x(n + 16, -1.0f), y(n + 16, -1.0f);
      kernels.xy(n, index.data(), si.data(), sx.data(), sy.data(), x.data(), y.data());
      for (size_t i = 0; i < n; ++i) {
        const uint32_t shuffled = nested_uniform_scramble(index[i], si[i]);
        // The definitions: Burley's nested uniform scramble of each Sobol coordinate.
        const float ex = fixed_to_unit_float(nested_uniform_scramble(sobol_dimension0(shuffled), sx[i]));
        const float ey = fixed_to_unit_float(nested_uniform_scramble(sobol_dimension1_reference(shuffled), sy[i]));
        ASSERT_EQ(float_bits(x[i]), float_bits(ex)) << kernels.name << " n " << n << " entry " << i;
        ASSERT_EQ(float_bits(y[i]), float_bits(ey)) << kernels.name << " n " << n << " entry " << i;
      }
      for (size_t i = n; i < n + 16; ++i) ASSERT_EQ(x[i], -1.0f) << kernels.name << " wrote past n " << n;
      for (size_t i = n; i < n + 16; ++i) ASSERT_EQ(y[i], -1.0f) << kernels.name << " wrote past n " << n;
      // The 1D value of a get_1d_2d pair: Sobol's third dimension of the shared shuffled index
      // (its generator matrix column by column, as Joe and Kuo define it), scrambled.
      std::vector<float> z(n + 16, -1.0f);
      kernels.z(n, index.data(), si.data(), sx.data(), z.data());
      for (size_t i = 0; i < n; ++i) {
        const uint32_t shuffled = nested_uniform_scramble(index[i], si[i]);
        uint32_t m[33] = {0, 1, 3}, sobol2 = 0;
        for (int k = 3; k <= 32; ++k) m[k] = (2 * m[k - 1]) ^ (4 * m[k - 2]) ^ m[k - 2];
        for (int k = 0; k < 32; ++k)
          if ((shuffled >> k) & 1u) sobol2 ^= uint32_t(uint64_t(m[k + 1]) << (31 - k));
        const float ez = fixed_to_unit_float(nested_uniform_scramble(sobol2, sx[i]));
        ASSERT_EQ(float_bits(z[i]), float_bits(ez)) << kernels.name << " n " << n << " entry " << i;
      }
      for (size_t i = n; i < n + 16; ++i) ASSERT_EQ(z[i], -1.0f) << kernels.name << " wrote past n " << n;
    }
  }
}

// The kernels of correlated multi-jittered points (cmj.h) give cmj.h's values to the bit.
TEST(SobolBatch, CmjKernelsAreTheDefinitionsToTheBit) {
  for (uint32_t bits : {1u, 2u, 5u, 6u, 11u, 24u}) {
    for (size_t n : {1u, 7u, 16u, 17u, 37u, 1280u}) {
      std::vector<uint32_t> index(n), si(n), sx(n), sy(n);
      XorShift32 random{977u + uint32_t(n) + bits};
      for (size_t i = 0; i < n; ++i) {
        index[i] = random.next() & ((1u << bits) - 1u);
        si[i] = random.next();
        sx[i] = random.next();
        sy[i] = random.next();
      }
      std::vector<float> x(n + 16, -1.0f), y(n + 16, -1.0f), z(n + 16, -1.0f);
      std::vector<uint32_t> cells(n + 16, 7u);
      cmj_cells_x_batch(n, bits, index.data(), si.data(), sx.data(), cells.data(), x.data());
      cmj_y_batch(n, bits, cells.data(), sy.data(), y.data());
      std::vector<uint32_t> rows(n);
      for (size_t i = 0; i < n; ++i) rows[i] = cmj_z_rows_seed(sx[i]);
      cmj_z_batch(n, bits, cells.data(), sx.data(), rows.data(), z.data());
      for (size_t i = 0; i < n; ++i) {
        const uint32_t cell = cmj_cell(index[i], bits, si[i]);
        ASSERT_EQ(cells[i], cell) << bits << " " << i;
        ASSERT_EQ(float_bits(x[i]), float_bits(fixed_to_unit_float(cmj_x(cell, bits, sx[i])))) << bits << " " << i;
        ASSERT_EQ(float_bits(y[i]), float_bits(fixed_to_unit_float(cmj_y(cell, bits, sy[i])))) << bits << " " << i;
        ASSERT_EQ(float_bits(z[i]), float_bits(fixed_to_unit_float(cmj_z(cell, bits, sx[i])))) << bits << " " << i;
      }
      for (size_t i = n; i < n + 16; ++i)
        ASSERT_TRUE(x[i] == -1.0f && y[i] == -1.0f && z[i] == -1.0f && cells[i] == 7u) << "past n";
    }
  }
}

// Paths of one pixel interleaved through BounceSamples/PrefetchedSampler take the values a
// Sampler gives each path alone: within the prefetched dimensions, past them (the fallback), and
// across the end of the sampler's cached dimensions (64); with the Sobol points and with CMJ's.
void expect_prefetched_paths_see_the_samplers_sequence(uint32_t cmj_bits) {
  constexpr int kPaths = 6;
  Sampler shared(42, cmj_bits), alone(42, cmj_bits);
  shared.start_pixel_sample(3, 5, 0);
  std::vector<Sampler::Cursor> cursors;
  for (int p = 0; p < kPaths; ++p) {
    shared.start_pixel_sample(3, 5, uint32_t(p * 11));
    cursors.push_back(shared.cursor());
  }
  std::vector<std::vector<float>> expected(kPaths), got(kPaths);
  // Bounces taking 1d,2d,1d,2d,1d (five dimensions), then seven (two past the prefetch), from
  // dimension 0 until well past 64.
  const int pattern[] = {1, 2, 1, 2, 1, 2, 1};
  for (int bounce = 0; bounce < 14; ++bounce) {
    const int takes = bounce % 2 ? 7 : 5;
    BounceSamples samples;
    // Five prefetched dimensions as a bounce has, or fewer as the camera stage asks for.
    samples.start(kPaths, bounce % 3 == 2 ? 2 : BounceSamples::kBounce);
    for (int p = 0; p < kPaths; ++p) samples.add(shared, cursors[p]);
    samples.compute();
    for (int p = 0; p < kPaths; ++p) {
      PrefetchedSampler s(shared, cursors[p], samples, size_t(p));
      take(s, pattern, takes, &got[p]);
      cursors[p] = s.cursor();
    }
  }
  for (int p = 0; p < kPaths; ++p) {
    alone.start_pixel_sample(3, 5, uint32_t(p * 11));
    for (int bounce = 0; bounce < 14; ++bounce) take(alone, pattern, bounce % 2 ? 7 : 5, &expected[p]);
    EXPECT_GT(alone.cursor().dimension, 64u);
    ASSERT_EQ(got[p].size(), expected[p].size());
    for (size_t i = 0; i < got[p].size(); ++i)
      ASSERT_EQ(float_bits(got[p][i]), float_bits(expected[p][i])) << "path " << p << " value " << i;
  }
}
TEST(SobolBatch, PrefetchedPathsSeeTheSamplersSequence) { expect_prefetched_paths_see_the_samplers_sequence(0); }
TEST(SobolBatch, PrefetchedCmjPathsSeeTheSamplersSequence) { expect_prefetched_paths_see_the_samplers_sequence(6); }

// A bounce's paths from several pixels and dimensions, in the orders a batch has them (runs of
// one pixel's samples, pixels alternating, a path a dimension ahead inside a run, one sampler
// moved to another pixel between two paths), with every pair computed: each path takes the
// values its own pixel's Sampler gives (BounceSamples takes a run's seeds once).
TEST(SobolBatch, PrefetchedRunsOfSeveralPixelsSeeTheirSamplers) {
  struct Path {
    int sampler, x, y;
    uint32_t index;
    int skip;  // dimensions taken before the bounce
  };
  const std::vector<Path> paths = {{0, 1, 2, 0, 0}, {0, 1, 2, 1, 0}, {0, 1, 2, 2, 0}, {1, 7, 3, 0, 0},
                                   {1, 7, 3, 1, 0}, {0, 1, 2, 3, 0}, {0, 1, 2, 4, 1}, {0, 1, 2, 5, 0},
                                   {2, 4, 4, 9, 0}, {2, 5, 4, 9, 0}, {2, 5, 4, 10, 0}, {1, 7, 3, 2, 0}};
  const int pattern[] = {3, 3, 1};
  Sampler samplers[3] = {Sampler(5), Sampler(5), Sampler(5)};
  BounceSamples samples;
  samples.start(paths.size(), BounceSamples::kBounce, BounceSamples::kBouncePairs, 0b00101u);
  std::vector<Sampler::Cursor> cursors;
  for (const Path& p : paths) {
    Sampler& s = samplers[p.sampler];
    s.start_pixel_sample(p.x, p.y, p.index);
    for (int d = 0; d < p.skip; ++d) s.get_1d();
    cursors.push_back(s.cursor());
    samples.add(s, cursors.back());
  }
  samples.compute();
  for (size_t k = 0; k < paths.size(); ++k) {
    const Path& p = paths[k];
    Sampler& s = samplers[p.sampler];
    s.start_pixel_sample(p.x, p.y, p.index);  // the pixel the path's sampler is on at its step
    std::vector<float> got, expected;
    PrefetchedSampler prefetched(s, cursors[k], samples, k);
    take(prefetched, pattern, 3, &got);
    Sampler alone(5);
    alone.start_pixel_sample(p.x, p.y, p.index);
    for (int d = 0; d < p.skip; ++d) alone.get_1d();
    take(alone, pattern, 3, &expected);
    ASSERT_EQ(got.size(), expected.size());
    for (size_t i = 0; i < got.size(); ++i)
      ASSERT_EQ(float_bits(got[i]), float_bits(expected[i])) << "path " << k << " value " << i;
  }
}

// A camera stage's runs (BounceSamples::add_run): runs of one pixel's consecutive samples, a
// run continuing the previous run's pixel (merged into its run), runs of other pixels between
// them, an empty run, and single adds after them: each path's values are its own sampler's, as
// if every path had been added alone.
TEST(SobolBatch, RunsOfSamplesSeeTheirSamplers) {
  struct RunOf {
    int sampler, x, y;
    uint32_t first, count;
  };
  const std::vector<RunOf> runs = {{0, 1, 2, 0, 5}, {0, 1, 2, 5, 3}, {1, 7, 3, 0, 2}, {1, 7, 3, 2, 0},
                                   {2, 4, 4, 9, 17}, {0, 1, 2, 8, 1}, {1, 7, 3, 2, 4}};
  const int pattern[] = {3, 2};  // with motion: the time with the film position, then the lens
  Sampler samplers[3] = {Sampler(11), Sampler(11), Sampler(11)};
  struct Path {
    int sampler, x, y;
    uint32_t index;
  };
  std::vector<Path> paths;
  for (const RunOf& r : runs)
    for (uint32_t j = 0; j < r.count; ++j) paths.push_back(Path{r.sampler, r.x, r.y, r.first + j});
  paths.push_back(Path{1, 7, 3, 6});  // single adds after the runs, the first continuing the last
  paths.push_back(Path{0, 6, 1, 3});
  BounceSamples samples;
  samples.start(paths.size(), 3, 0b001u, 0b001u);
  for (const RunOf& r : runs) {
    Sampler& s = samplers[r.sampler];
    s.start_pixel_sample(r.x, r.y, r.first);
    samples.add_run(s, r.first, r.count, 0);
  }
  for (size_t k = paths.size() - 2; k < paths.size(); ++k) {
    Sampler& s = samplers[paths[k].sampler];
    s.start_pixel_sample(paths[k].x, paths[k].y, paths[k].index);
    samples.add(s, s.cursor());
  }
  samples.compute();
  for (size_t k = 0; k < paths.size(); ++k) {
    const Path& p = paths[k];
    Sampler& s = samplers[p.sampler];
    s.start_pixel_sample(p.x, p.y, p.index);
    std::vector<float> got, expected;
    PrefetchedSampler prefetched(s, Sampler::Cursor{p.index, 0}, samples, k);
    take(prefetched, pattern, 2, &got);
    Sampler alone(11);
    alone.start_pixel_sample(p.x, p.y, p.index);
    take(alone, pattern, 2, &expected);
    ASSERT_EQ(got.size(), expected.size());
    for (size_t i = 0; i < got.size(); ++i)
      ASSERT_EQ(float_bits(got[i]), float_bits(expected[i])) << "path " << k << " value " << i;
  }
}

// get_1d_2d pairs through BounceSamples/PrefetchedSampler: a bounce's light pair and lobe pair
// (pattern 3 at dimensions 0 and 2), a surface with Dirac lobes only (its pair at 0, Russian
// roulette's plain 1D value at 2, where the layout has the lobe pair), a pair where none was
// laid out (dimension 1), with every subset of the pairs computed, 2D values computed only where
// a bounce reads them (2D values at dimensions 0 and 4 come from the sampler, and the values
// after them from the prefetched ones again), 1D values left out or not (the pairs' first
// dimensions, the roulette's, all that may be: 1D values read there come from the sampler): the
// values a Sampler gives, with the Sobol points and with CMJ's (32 samples).
TEST(SobolBatch, PrefetchedPairsSeeTheSamplersSequence) {
  constexpr int kPaths = 5;
  const int patterns[4][4] = {{3, 3, 1, 0}, {3, 1, 1, 2}, {1, 3, 2, 1}, {2, 2, 1, 1}};
  const int takes[4] = {3, 4, 4, 4};
  for (uint32_t computed = 0; computed < 16; ++computed) {
    for (int which = 0; which < 4; ++which) {
      for (uint32_t unread_x : {0u, 0b00001u, 0b00100u, 0b00101u, 0b10000u, 0b11111u}) {
        const uint32_t cmj_bits = computed >= 8 ? 5u : 0u;
        SCOPED_TRACE(testing::Message() << "computed " << computed % 8 << ", pattern " << which
                                        << ", cmj " << cmj_bits << ", unread x " << unread_x);
        Sampler shared(9, cmj_bits), alone(9, cmj_bits);
        std::vector<Sampler::Cursor> cursors;
        for (int p = 0; p < kPaths; ++p) {
          shared.start_pixel_sample(4, 1, uint32_t(p * 7 + 1));
          for (int d = 0; d < p; ++d) shared.get_1d();  // paths at different dimensions
          cursors.push_back(shared.cursor());
        }
        BounceSamples samples;
        samples.start(kPaths, BounceSamples::kBounce, BounceSamples::kBouncePairs, computed % 8,
                      BounceSamples::kBounceTwoD, unread_x);
        for (int p = 0; p < kPaths; ++p) samples.add(shared, cursors[p]);
        samples.compute();
        for (int p = 0; p < kPaths; ++p) {
          std::vector<float> got, expected;
          PrefetchedSampler s(shared, cursors[p], samples, size_t(p));
          take(s, patterns[which], takes[which], &got);
          alone.start_pixel_sample(4, 1, uint32_t(p * 7 + 1));
          for (int d = 0; d < p; ++d) alone.get_1d();
          take(alone, patterns[which], takes[which], &expected);
          EXPECT_EQ(s.cursor().dimension, alone.cursor().dimension);
          ASSERT_EQ(got.size(), expected.size());
          for (size_t i = 0; i < got.size(); ++i)
            ASSERT_EQ(float_bits(got[i]), float_bits(expected[i])) << "path " << p << " value " << i;
        }
      }
    }
  }
}

}  // namespace
}  // namespace penumbra::test
