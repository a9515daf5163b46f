// The program cache builds an entry once when several builders miss it at the same time (a
// parallel test run on cold caches, several renders started together): the first takes the
// entry's lock and builds, the others wait for it and read what it wrote. flock locks belong to
// open file descriptions, so two threads of one process exclude each other as two processes do.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "cl/kernel_source.hpp"
#include "cl/program_cache.hpp"
#include "support.hpp"

namespace test_program_cache_lock {

namespace {

using lucent::cl_util::ProgramBuildInfo;

constexpr int kBuilders = 3;

// Runs build(ctx, i) for i < kBuilders at once, each in its own thread with its own context (all
// start together); returns each one's exception message ("" when none).
std::vector<std::string> run_builders(
    const std::function<void(lucent::cl_util::Context&, int)>& build) {
  std::vector<std::unique_ptr<lucent::cl_util::Context>> contexts;
  for (int i = 0; i < kBuilders; ++i)
    contexts.push_back(std::make_unique<lucent::cl_util::Context>(""));
  std::vector<std::string> errors(kBuilders);
  std::atomic<int> ready{0};
  std::vector<std::thread> threads;
  for (int i = 0; i < kBuilders; ++i)
    threads.emplace_back([&, i] {
      ++ready;
      while (ready.load() < kBuilders) std::this_thread::yield();  // all miss at once
      try {
        build(*contexts[i], i);
      } catch (const std::exception& e) {
        errors[i] = e.what();
      }
    });
  for (auto& t : threads) t.join();
  return errors;
}

TEST(ProgramCacheLock, SimultaneousMissesBuildOnce) {
  const std::string dir = lucent::test::temp_dir() + "/cache";
  const std::string src = lucent::detail::assemble_kernel_source("test/layout_probe.cl");
  // an option of its own: no other test's entry can be there already
  const std::string options = "-cl-std=CL1.2 -D LC_PROGRAM_CACHE_LOCK_TEST";

  std::vector<ProgramBuildInfo> info(kBuilders);
  std::vector<std::string> errors = run_builders([&](lucent::cl_util::Context& ctx, int i) {
    lucent::cl_util::build_program_cached(ctx, src, options, dir, &info[i]);
  });

  int built = 0;
  for (int i = 0; i < kBuilders; ++i) {
    EXPECT_EQ(errors[i], "") << "builder " << i;
    EXPECT_EQ(info[i].cache_file, info[0].cache_file);
    if (!info[i].cache_hit) ++built;
  }
  EXPECT_EQ(built, 1) << "each builder that missed compiled the program itself";
  EXPECT_TRUE(std::filesystem::exists(info[0].cache_file));
}

// Without entries (a driver that caches its own builds, cl/program_cache.hpp) the lock is still
// taken, and held by the deferred entry until store(): builders of the same program run one after
// the other (each from its build's return to its store), and no entry is written.
TEST(ProgramCacheLock, LockOnlyBuildsTakeTurns) {
  const std::string dir = lucent::test::temp_dir() + "/cache";
  const std::string src = lucent::detail::assemble_kernel_source("test/layout_probe.cl");
  const std::string options = "-cl-std=CL1.2 -D LC_PROGRAM_CACHE_LOCK_ONLY_TEST";
  using clock = std::chrono::steady_clock;
  std::vector<std::pair<clock::time_point, clock::time_point>> held(kBuilders);
  std::vector<std::string> errors = run_builders([&](lucent::cl_util::Context& ctx, int i) {
    lucent::cl_util::DeferredEntry entry;
    ProgramBuildInfo info;
    cl::Program p =
        lucent::cl_util::build_program_cached(ctx, src, options, dir, &info, &entry, false);
    held[i].first = clock::now();
    if (!entry.pending() || info.cache_hit || !info.cache_file.empty())
      throw std::runtime_error("no lock held, or an entry used");
    std::this_thread::sleep_for(std::chrono::milliseconds(30));
    held[i].second = clock::now();
    entry.store(p);
  });
  for (int i = 0; i < kBuilders; ++i) EXPECT_EQ(errors[i], "") << "builder " << i;
  std::sort(held.begin(), held.end());
  for (int i = 1; i < kBuilders; ++i)
    EXPECT_GE(held[i].first, held[i - 1].second) << "two builders held the lock at once";
  for (const auto& e : std::filesystem::directory_iterator(dir))
    EXPECT_EQ(e.path().extension(), ".lock") << e.path();
}

// A lock file removed while a builder waits on it (by `cache clear`, or by an eviction that took
// the free lock an instant before the builder did) is opened again: the builder that waited on the
// removed file must not build beside one that locked the new file, but wait for it and read its
// entry.
TEST(ProgramCacheLock, ALockRemovedUnderAWaitingBuilderIsOpenedAgain) {
  const std::string dir = lucent::test::temp_dir() + "/cache";
  const std::string src = lucent::detail::assemble_kernel_source("test/layout_probe.cl");
  const std::string options = "-cl-std=CL1.2 -D LC_PROGRAM_CACHE_REMOVED_LOCK_TEST";
  lucent::cl_util::Context first_ctx(""), waiter_ctx(""), second_ctx("");
  // a first builder holds the lock (deferred: until it stores or drops its entry)
  auto first = std::make_unique<lucent::cl_util::DeferredEntry>();
  ProgramBuildInfo first_info, waiter_info, second_info;
  lucent::cl_util::build_program_cached(first_ctx, src, options, dir, &first_info, first.get());
  ASSERT_TRUE(first->pending());
  std::string waiter_error;
  std::thread waiter([&] {
    waiter_error = lucent::test::error_of([&] {
      lucent::cl_util::build_program_cached(waiter_ctx, src, options, dir, &waiter_info);
    });
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // the waiter waits on the lock
  std::filesystem::remove(first_info.cache_file + ".lock");
  // a second builder locks a new file of that name and builds; the first gives up unstored
  lucent::cl_util::DeferredEntry second;
  cl::Program p =
      lucent::cl_util::build_program_cached(second_ctx, src, options, dir, &second_info, &second);
  ASSERT_TRUE(second.pending());
  first.reset();
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  second.store(p);
  waiter.join();
  EXPECT_EQ(waiter_error, "");
  EXPECT_FALSE(second_info.cache_hit);
  EXPECT_TRUE(waiter_info.cache_hit) << "the waiter built beside the second builder";
}

// Evictions racing loads of the entry they remove: each load that loses the race rebuilds (and
// writes the entry again); none fails or gets a program that does not run.
TEST(ProgramCacheLock, EvictionsRacingLoadsCostRebuilds) {
  const std::string dir = lucent::test::temp_dir() + "/cache";
  const std::string src = lucent::detail::assemble_kernel_source("test/layout_probe.cl");
  const std::string options = "-cl-std=CL1.2 -D LC_PROGRAM_CACHE_EVICTION_RACE_TEST";
  std::atomic<bool> done{false};
  std::atomic<int> hits{0}, builds{0}, evicted{0}, loaders{kBuilders - 1};
  std::vector<std::string> errors = run_builders([&](lucent::cl_util::Context& ctx, int i) {
    if (i == 0) {  // the evictor: everything it can, every few milliseconds
      while (!done) {
        evicted += lucent::cl_util::evict_program_cache(dir, 1);
        std::this_thread::sleep_for(std::chrono::milliseconds(3));
      }
      return;
    }
    // the last loader to end, by an error too, ends the evictor (a loader that threw left it
    // running, and the test hung in join)
    struct LastLoaderEndsTheEvictor {
      std::atomic<int>& loaders;
      std::atomic<bool>& done;
      ~LastLoaderEndsTheEvictor() {
        if (--loaders == 0) done = true;
      }
    } last{loaders, done};
    // 1.5 s of loads after the loader's first program: a cold build alone took 1.7 s on a loaded
    // CI machine, and a window counted from the start then held one build and no load at all
    std::optional<std::chrono::steady_clock::time_point> t0;
    while (!t0 || std::chrono::steady_clock::now() - *t0 < std::chrono::milliseconds(1500)) {
      ProgramBuildInfo info;
      cl::Program p = lucent::cl_util::build_program_cached(ctx, src, options, dir, &info);
      cl::Kernel k(p, "lucent_layout_probe");
      cl::Buffer out(ctx.context, CL_MEM_WRITE_ONLY, 4096);
      k.setArg(0, out);
      ctx.queue.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(1), cl::NullRange);
      unsigned v = 0;
      ctx.queue.enqueueReadBuffer(out, CL_TRUE, 0, sizeof v, &v);
      if (v != 64u) throw std::runtime_error("the program does not run: " + std::to_string(v));
      if (!info.note.empty()) throw std::runtime_error("a damaged entry: " + info.note);
      ++(info.cache_hit ? hits : builds);
      if (!t0) t0 = std::chrono::steady_clock::now();
    }
  });
  done = true;
  for (int i = 0; i < kBuilders; ++i) EXPECT_EQ(errors[i], "") << "builder " << i;
  EXPECT_GT(evicted.load(), 1);
  EXPECT_GT(builds.load(), 1) << "no load lost a race with an eviction";
  EXPECT_GT(hits.load(), 0);
}

}  // namespace

}  // namespace test_program_cache_lock
