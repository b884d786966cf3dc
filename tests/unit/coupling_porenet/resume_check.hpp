// Resume and thread checks of the 3D DEM <-> pore network coupling (DemPorenet3D), for any specimen
// maker: make(platen_v) returns a specimen (->sys) whose loops run in parallel, state_of(sys, c) the
// values compared.
#pragma once
#include <gtest/gtest.h>
#include <omp.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "coupling/porenet/dem_porenet3d.hpp"
#include "dem/dem_checkpoint.hpp"

namespace ff::test {

// Checkpoints (DEM + coupling) `sys` and `c`, loads both into a fresh specimen at rest (make(0)), runs it
// `steps` more steps and returns its state.
template <class Make, class State>
std::vector<Real> resumed_state(Make make, const dem::DemSystem& sys, const coupling::DemPorenet3D& c,
                                const coupling::Porenet3DParams& prm, int steps, const std::string& file,
                                State state_of) {
  const auto path = std::filesystem::temp_directory_path() / file;
  {
    CheckpointWriter w(path);
    dem::save_dem(w, sys);
    c.save(w);
    w.commit();
  }
  auto resumed = make(0.0);
  CheckpointReader r(path);
  dem::load_dem(r, resumed->sys);
  coupling::DemPorenet3D c2;
  c2.load(r, resumed->sys, prm);
  c2.run(resumed->sys, steps);
  std::filesystem::remove(path);
  return state_of(resumed->sys, c2);
}

// n1 + n2 steps of a specimen compacted at 0.05 m/s on two threads (at least one retriangulation), against
// the same on one thread, and against n1 steps, a checkpoint, a resume and n2 more: every value the same.
template <class Make, class State>
void expect_resume_and_threads_identical(Make make, const coupling::Porenet3DParams& prm, int n1, int n2,
                                         State state_of, const std::string& file, const char* label) {
  omp_set_num_threads(2);
  auto ref = make(0.05);
  coupling::DemPorenet3D cref;
  cref.init(ref->sys, prm);
  cref.run(ref->sys, n1 + n2);
  const auto a = state_of(ref->sys, cref);
  EXPECT_GE(cref.stats().retriangulations, 1);

  omp_set_num_threads(1);
  auto one = make(0.05);
  coupling::DemPorenet3D c1;
  c1.init(one->sys, prm);
  c1.run(one->sys, n1);
  const auto b = resumed_state(make, one->sys, c1, prm, n2, file, state_of);
  c1.run(one->sys, n2);
  const auto d = state_of(one->sys, c1);
  ASSERT_EQ(a.size(), d.size());
  ASSERT_EQ(b.size(), d.size());
  long diff_resume = 0, diff_threads = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    diff_resume += b[k] != d[k];
    diff_threads += a[k] != d[k];
  }
  std::printf("%s resume: %ld values differ; 1 vs 2 threads: %ld differ (of %zu); %ld retriangulations\n", label,
              diff_resume, diff_threads, a.size(), c1.stats().retriangulations);
  EXPECT_EQ(diff_resume, 0) << "resumed vs uninterrupted";
  EXPECT_EQ(diff_threads, 0) << "2 threads vs 1 thread";
  omp_set_num_threads(2);
}

}  // namespace ff::test
