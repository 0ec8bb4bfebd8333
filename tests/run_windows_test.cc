// Tests of run/windows.h and run/sample_clock.h: a simulated run reduced to windows (occurrences,
// trimming, temperature spans, turns and their noise), the sample clock under lost samples, jitter
// and drift, saturated outputs left out; part of run_test.
#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "imufit/model/constants.h"
#include "imufit/run/sample_clock.h"
#include "imufit/run/windows.h"
#include "imufit/sim/simulator.h"
#include "sim_runs.h"
#include "test_models.h"

namespace imufit {
namespace {

using testing::FastRateWindows;
using testing::kGyroFullScaleCounts;
using testing::MemsNoise;
using testing::Simulate;
using testing::Site;
using testing::SixPositionPlan;

// ---------------------------------------------------------------- windows

TEST(Windows, OccurrencesTrimmingAndTemperatureSpans) {
  WindowOptions options;
  options.trim_s = 0.5;
  options.max_temp_span_c = 1.0;
  options.min_samples = 5;
  WindowBuilder builder(options);
  Sample s;
  double t = 0.0;
  const auto add = [&](int segment, int count, double temp_start, double temp_step) {
    for (int i = 0; i < count; ++i, t += 0.125) {  // exact binary times
      s.time_s = t;
      s.segment = segment;
      s.temp_c = temp_start + temp_step * i;
      s.gyro = Eigen::Vector3d(i % 2, 1.0, 2.0);
      s.accel = Eigen::Vector3d(3.0, 4.0, 5.0);
      builder.Add(s);
    }
  };
  add(3, 20, 25.0, 0.0);   // 4 trimmed (0 .. 0.375 s), 16 kept
  add(-1, 10, 25.0, 0.0);  // transition
  add(3, 30, 20.0, 0.1);   // second occurrence; ramp of 0.1 degC per sample -> several windows
  add(4, 7, 25.0, 0.0);    // 4 trimmed, 3 left: a short window
  const std::vector<Window> windows = builder.Finish();
  const WindowStats& stats = builder.stats();
  EXPECT_EQ(stats.samples, 67);
  EXPECT_EQ(stats.transition_samples, 10);
  EXPECT_EQ(stats.trimmed_samples, 12);
  // Segment 4's three samples are left out, counted; the last 4 samples of the ramp (26 kept =
  // 11 + 11 + 4) are merged into the window before them, not dropped.
  EXPECT_EQ(stats.short_windows, 1);
  EXPECT_EQ(stats.short_samples, 3);
  EXPECT_EQ(stats.merged_remainders, 1);
  EXPECT_EQ(stats.window_samples, 16 + 26);
  EXPECT_EQ(AccountedSamples(stats), stats.samples);
  ASSERT_EQ(windows.size(), 3u);
  EXPECT_EQ(windows[2].samples, 15);
  EXPECT_NEAR(windows[2].max_temp_c - windows[2].min_temp_c, 1.4, 1e-12);
  EXPECT_EQ(windows[0].segment, 3);
  EXPECT_EQ(windows[0].occurrence, 0);
  EXPECT_EQ(windows[0].samples, 16);
  EXPECT_NEAR(windows[0].gyro_mean.x(), 0.5, 1e-15);  // i = 4..19: eight odd values of 16
  EXPECT_NEAR(windows[0].gyro_std.x(), std::sqrt(0.25 * 16.0 / 15.0), 1e-15);
  EXPECT_EQ(windows[0].gyro_std.y(), 0.0);
  EXPECT_EQ(windows[0].min_temp_c, 25.0);
  EXPECT_EQ(windows[0].max_temp_c, 25.0);
  EXPECT_NEAR(windows[1].min_temp_c, 20.4, 1e-12);  // the ramp's first kept sample
  for (size_t w = 1; w < windows.size(); ++w) {
    EXPECT_EQ(windows[w].occurrence, 1);
  }
  EXPECT_EQ(windows[1].samples, 11);  // a 1 degC span at 0.1 degC per sample
  EXPECT_NEAR(windows[1].max_temp_c - windows[1].min_temp_c, 1.0, 1e-12);
}

// A merged remainder's statistics are those of one window over all its samples (pooled mean,
// standard deviation and temperature), to rounding.
TEST(Windows, AMergedRemainderIsOneWindowOverAllItsSamples) {
  constexpr double kRounding = 1e-12;  // absolute, on values of order 1
  WindowOptions options;
  options.trim_s = 0.0;
  options.max_duration_s = 1.0;
  options.min_samples = 20;
  WindowBuilder builder(options);
  std::mt19937_64 engine(11);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<Sample> samples;
  for (int i = 0; i < 115; ++i) {  // 1.15 s at 100 Hz: a window of 100 and a remainder of 15, merged
    Sample s;
    s.time_s = 0.01 * i;
    s.segment = 1;
    s.temp_c = 25.0 + 0.001 * i;
    s.gyro = Eigen::Vector3d(noise(engine), 2.0 + noise(engine), -1.0);
    s.accel = Eigen::Vector3d(0.0, 0.0, 9.8 + 0.01 * noise(engine));
    samples.push_back(s);
  }
  for (const Sample& s : samples) builder.Add(s);
  const std::vector<Window> windows = builder.Finish();
  ASSERT_EQ(windows.size(), 1u);
  EXPECT_EQ(windows[0].samples, 115);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero(), square = Eigen::Vector3d::Zero();
  double temp = 0.0;
  for (const Sample& s : samples) {
    mean += s.gyro / 115.0;
    temp += s.temp_c / 115.0;
  }
  for (const Sample& s : samples) square += (s.gyro - mean).cwiseAbs2() / 114.0;
  EXPECT_LT((windows[0].gyro_mean - mean).norm(), kRounding);
  EXPECT_LT((windows[0].gyro_std - square.cwiseSqrt()).norm(), kRounding);
  EXPECT_NEAR(windows[0].temp_c, temp, kRounding);
  EXPECT_EQ(windows[0].end_s, samples.back().time_s);
  EXPECT_EQ(builder.stats().merged_remainders, 1);
  EXPECT_EQ(AccountedSamples(builder.stats()), 115);
}

// On a ramp so fast that the span passes in fewer than min_samples, windows span more instead of
// being dropped whole: no sample of a dwell is lost.
TEST(Windows, AFastRampLosesNoSample) {
  WindowOptions options;  // 0.5 degC span, 20 samples
  options.trim_s = 0.0;
  WindowBuilder builder(options);
  Sample s;
  for (int i = 0; i < 200; ++i) {  // 0.1 degC per sample: the span passes after 6 samples
    s.time_s = 0.01 * i;
    s.segment = 1;
    s.temp_c = 25.0 + 0.1 * i;
    builder.Add(s);
  }
  const std::vector<Window> windows = builder.Finish();
  EXPECT_EQ(builder.stats().short_windows, 0);
  EXPECT_EQ(builder.stats().window_samples, 200);
  ASSERT_EQ(windows.size(), 10u);
  for (const Window& w : windows) EXPECT_EQ(w.samples, 20);
}

// Every reason a sample is left out is counted, and a person reads each with its count.
TEST(Windows, EverySampleLeftOutIsCountedWithItsReason) {
  const std::vector<TableSegment> segments = SixPositionPlan();
  SimulationOptions schedule;
  schedule.dwell_s = 0.6;  // 60 samples, 50 trimmed: 10 left, shorter than 20
  schedule.transition_s = 0.5;
  schedule.soak_temps_c = {25.0};
  WindowBuilder builder(WindowOptions(), segments);
  SimulateRun(schedule, Site(), segments, SensorModel::Identity(),
              [&](const Sample& raw, const SegmentTruth&) { builder.Add(raw); });
  const std::vector<Window> windows = builder.Finish();
  const WindowStats& stats = builder.stats();
  EXPECT_TRUE(windows.empty());
  EXPECT_EQ(stats.short_windows, static_cast<long long>(segments.size()));
  // About 10 a segment (a stamp's rounding may trim one more).
  EXPECT_EQ(stats.short_samples, stats.samples - stats.transition_samples - stats.trimmed_samples);
  EXPECT_NEAR(static_cast<double>(stats.short_samples), 10.0 * segments.size(), 2.0);
  EXPECT_EQ(AccountedSamples(stats), stats.samples);
  const std::string note = LeftOutNote(stats, WindowOptions());
  EXPECT_NE(note.find(std::to_string(stats.short_samples) + " in " + std::to_string(segments.size()) +
                      " segment occurrences shorter than 20 samples (--window-min-samples)"),
            std::string::npos)
      << note;
  EXPECT_NE(note.find("trimmed after moves (--trim 0.5 s)"), std::string::npos) << note;
}

TEST(Windows, ATurnIsOneWholeOccurrenceWithItsNoiseFromSecondDifferences) {
  std::vector<TableSegment> segments(2);
  segments[0].id = 1;
  segments[1].id = 2;
  segments[1].angle_rad = 2.0 * M_PI;
  WindowOptions options;
  options.trim_s = 0.5;
  options.max_temp_span_c = 0.1;
  options.max_duration_s = 1.0;
  options.min_samples = 5;
  WindowBuilder builder(options, segments);
  Sample s;
  double t = 0.0;
  // A turn of 400 samples (4 s at 100 Hz): ramping temperature and a rate profile that a
  // standard deviation would take for noise; +-1 alternating noise on top.
  for (int i = 0; i < 400; ++i, t += 0.01) {
    s.time_s = t;
    s.segment = 2;
    s.temp_c = 25.0 + 0.01 * i;
    const double profile = 1000.0 * (1.0 - std::cos(2.0 * M_PI * i / 400.0));
    s.gyro = Eigen::Vector3d(profile + (i % 2 ? 1.0 : -1.0), 0.0, 0.0);
    s.accel = Eigen::Vector3d::Zero();
    builder.Add(s);
  }
  const std::vector<Window> windows = builder.Finish();
  ASSERT_EQ(windows.size(), 1u);
  EXPECT_EQ(windows[0].samples, 400);
  EXPECT_TRUE(windows[0].whole_occurrence);
  EXPECT_NEAR(windows[0].DurationS(), 4.0, 1e-12);
  EXPECT_GT(windows[0].gyro_std.x(), 500.0);  // the signal
  // Alternating +-1 has second differences of +-4: sqrt(16 / 6) per sample; the profile adds
  // (2 pi / 400)^2 * 1000 = 0.25 at most to a second difference.
  EXPECT_NEAR(windows[0].gyro_noise.x(), std::sqrt(16.0 / 6.0), 0.15);
  EXPECT_EQ(builder.stats().trimmed_samples, 0);
}

// Stamps of a 100 Hz log: slots 0..n-1 less `lost` ones (the slots kept in `slots`), each off its
// slot by a uniform jitter.
std::vector<double> Stamps(int n, double jitter_s, const std::vector<int>& lost,
                           std::vector<long long>* slots, uint64_t seed) {
  std::mt19937_64 engine(seed);
  std::uniform_real_distribution<double> jitter(-jitter_s, jitter_s);
  std::vector<double> time_s;
  for (int k = 0; k < n; ++k) {
    const double offset = jitter(engine);
    if (std::find(lost.begin(), lost.end(), k) != lost.end()) continue;
    time_s.push_back(1.7e9 + 0.01 * k + offset);  // Unix time stamps, as a host writes them
    slots->push_back(k);
  }
  return time_s;
}

TEST(SampleClock, FindsLostSamplesUnderJitterOfUpToFortyPercentOfAnInterval) {
  // A 20 minute log at 100 Hz with 1 % of its samples lost (some in bursts), none while the grid
  // is acquired.
  std::mt19937_64 engine(11);
  std::vector<int> lost;
  for (int k = SampleClock::kAcquire; k < 120000; ++k) {
    if (std::uniform_real_distribution<double>(0.0, 1.0)(engine) < 0.004) {
      for (int j = 0; j < 1 + k % 4; ++j) lost.push_back(k + j);
      k += 4;
    }
  }
  for (const double jitter_s : {0.0, 0.001, 0.003, 0.004}) {
    std::vector<long long> slots;
    const std::vector<double> time_s = Stamps(120000, jitter_s, lost, &slots, 5);
    SampleClock clock;
    long long misplaced = 0, off_grid = 0, slot = -1;
    for (size_t i = 0; i < time_s.size(); ++i) {
      slot += clock.Place(time_s[i]);
      misplaced += slot != slots[i];
      off_grid += !clock.on_grid();
    }
    EXPECT_EQ(misplaced, 0) << "jitter " << jitter_s << " s";
    EXPECT_EQ(off_grid, 0) << "jitter " << jitter_s << " s";
    // The interval from the last ~20000 stamps: jitter / sqrt(N^3 / 12) ~ 1e-9 s.
    EXPECT_NEAR(clock.interval_s(), 0.01, 1e-8) << "jitter " << jitter_s << " s";
  }
}

TEST(SampleClock, AcquiresTheGridThroughLostSamplesAndRelocksAfterAJump) {
  // Every tenth of the first stamps lost, 0.4 intervals of jitter: a line through stamps taken as
  // consecutive would be tilted by a tenth; the phases are not.
  std::vector<int> lost;
  for (int k = 0; k < 600; k += 10) lost.push_back(k + 1);
  std::vector<long long> slots;
  std::vector<double> time_s = Stamps(3000, 0.004, lost, &slots, 9);
  const size_t jump = time_s.size();
  // Then the host's clock jumps forward by 37.5 intervals, half an interval off the grid, with no
  // sample lost at the jump, and the log goes on with less jitter than that half interval (a jump
  // smaller than the jitter is jitter). After the relock one sample in fifty is lost.
  constexpr double kJumpS = 0.375;
  constexpr int kRelockedBy = SampleClock::kRelock + SampleClock::kAcquire;  // stamps after the jump
  std::mt19937_64 engine(10);
  std::uniform_real_distribution<double> small_jitter(-0.0001, 0.0001);
  long long next_slot = slots.back() + 1;
  long long lost_after_relock = 0;
  for (int k = 1; k <= 3000; ++k, ++next_slot) {
    if (k > kRelockedBy + 100 && k % 50 == 25) {
      ++lost_after_relock;
      continue;
    }
    time_s.push_back(1.7e9 + 0.01 * static_cast<double>(next_slot) + kJumpS + small_jitter(engine));
    slots.push_back(next_slot);
  }
  SampleClock clock;
  long long slot = slots[SampleClock::kAcquire - 1];
  long long misplaced = 0, misplaced_after_relock = 0, off_grid_after_jump = 0, found_after_relock = 0;
  for (size_t i = 0; i < time_s.size(); ++i) {
    const long long step = clock.Place(time_s[i]);
    if (i >= jump) off_grid_after_jump += !clock.on_grid();
    if (i < SampleClock::kAcquire) continue;
    slot += step;
    if (i < jump) misplaced += slot != slots[i];
    // The slots after the relock are counted from the new grid: each step as the truth's.
    if (i >= jump + kRelockedBy) {
      misplaced_after_relock += step != slots[i] - slots[i - 1];
      found_after_relock += step - 1;
    }
  }
  EXPECT_EQ(misplaced, 0);
  // The jump moves every stamp off the old grid until kRelock in a row start a new acquisition; on
  // the new grid none is off it, and every lost sample is found.
  EXPECT_EQ(off_grid_after_jump, SampleClock::kRelock);
  EXPECT_EQ(misplaced_after_relock, 0);
  EXPECT_EQ(found_after_relock, lost_after_relock);
  EXPECT_GT(lost_after_relock, 40);
  EXPECT_NEAR(clock.interval_s(), 0.01, 1e-7);
}

TEST(SampleClock, FollowsADriftingClockAndFlagsBunchedStamps) {
  // A host clock 200 ppm fast and slowing by 100 ppm per hour: still every slot found.
  SampleClock drifting;
  long long misplaced = 0;
  for (long long k = 0; k < 360000; ++k) {
    const double t_s = 0.01 * static_cast<double>(k);
    misplaced += drifting.Place(t_s * (1.0 + 2e-4 - 1e-4 * t_s / 3600.0)) != 1;
  }
  EXPECT_EQ(misplaced, 0);
  // A host that stamps on arrival, ten samples a packet: off the grid.
  SampleClock bunched;
  long long off_grid = 0;
  for (int k = 0; k < 4000; ++k) {
    bunched.Place(0.1 * (k / 10) + 1e-6 * (k % 10));
    off_grid += !bunched.on_grid();
  }
  EXPECT_GT(off_grid, 1000);
}

TEST(Windows, ATurnWithBunchedStampsTakesOneIntervalASample) {
  std::vector<TableSegment> segments(1);
  segments[0].id = 7;
  segments[0].angle_rad = 2.0 * M_PI;
  WindowBuilder builder(WindowOptions(), segments);
  Sample s;
  s.segment = 7;
  for (int k = 0; k < 4000; ++k) {
    s.time_s = 0.1 * (k / 10) + 1e-6 * (k % 10);
    builder.Add(s);
  }
  const std::vector<Window> windows = builder.Finish();
  ASSERT_EQ(windows.size(), 1u);
  EXPECT_EQ(windows[0].lost_samples, 0);
  EXPECT_NEAR(windows[0].DurationS(), 40.0, 1e-3);
  EXPECT_FALSE(builder.stats().StampsOnGrid());
  const std::string note = TimeStampNote(builder.stats());
  EXPECT_NE(
      note.find(
          "lost samples cannot be told from jitter, so in the turns each sample is taken as one interval"),
      std::string::npos)
      << note;
}

// A 360 deg turn of 4 s at 100 Hz (raised-cosine rate, at rest at both ends) after a rest of 60 s,
// with `lost` samples (slots counted from the turn's start) missing from the log.
Window TurnWindow(double jitter_s, const std::vector<int>& lost, const WindowOptions& options,
                  WindowStats* stats) {
  std::vector<TableSegment> segments(2);
  segments[0].id = 1;
  segments[1].id = 7;
  segments[1].angle_rad = 2.0 * M_PI;
  WindowBuilder builder(options, segments);
  std::vector<int> lost_in_run;
  for (int k : lost) lost_in_run.push_back(k + 6000);
  std::vector<long long> slots;
  const std::vector<double> time_s = Stamps(6401, jitter_s, lost_in_run, &slots, 3);
  Sample s;
  s.temp_c = 25.0;
  s.accel = Eigen::Vector3d(0.0, 0.0, 9.8);
  for (size_t i = 0; i < time_s.size(); ++i) {
    const double u = static_cast<double>(slots[i] - 6000) / 400.0;
    s.segment = u < 0.0 ? 1 : 7;
    s.time_s = time_s[i];
    s.gyro = Eigen::Vector3d(u < 0.0 ? 0.0 : 0.5 * M_PI * (1.0 - std::cos(2.0 * M_PI * u)), 0.0, 0.0);
    builder.Add(s);
  }
  const std::vector<Window> windows = builder.Finish();
  *stats = builder.stats();
  for (const Window& w : windows) {
    if (w.segment == 7) return w;
  }
  return Window();
}

TEST(Windows, ATurnKeepsItsAngleWhenSamplesAreLost) {
  const std::vector<int> lost = {57, 150, 151, 152, 203, 260};  // near the peak rate, one of 3
  for (const double jitter_s : {0.0, 0.003}) {
    WindowStats stats;
    const Window window = TurnWindow(jitter_s, lost, WindowOptions(), &stats);
    ASSERT_EQ(window.samples, 401 - 6) << "jitter " << jitter_s << " s";
    EXPECT_EQ(window.lost_samples, 6);
    EXPECT_NEAR(window.longest_gap_s, 0.03, 1e-6);
    EXPECT_EQ(stats.lost_samples, 6);
    EXPECT_EQ(stats.gaps, 4);
    // Each slot stands for 0.01 s: the raised cosine's 401 samples sum to its integral exactly, and
    // linear interpolation across the gaps errs by sum g^3 / 12 * (pi/2) (2 pi / 4)^2 = 3e-5 rad at
    // most, where each lost sample would have taken up to pi/100 rad with it. The interval comes
    // from the 6400 stamps so far: 3 ms of jitter leaves it uncertain by about 1.3 ppm.
    const double angle_rad = window.gyro_mean.x() * window.DurationS();
    EXPECT_NEAR(angle_rad, 2.0 * M_PI, 3e-5 + 2.0 * M_PI * 4e-6) << "jitter " << jitter_s << " s";
    EXPECT_NEAR(window.DurationS(), 4.01, 4.01 * 4e-6);
    const std::string note = TimeStampNote(stats);
    EXPECT_NE(note.find("6 samples lost in 4 gaps"), std::string::npos) << note;
  }
}

TEST(Windows, ATurnWithALongGapIsDroppedAndSaysSo) {
  std::vector<int> lost;
  for (int k = 180; k < 190; ++k) lost.push_back(k);  // 0.1 s at the peak rate
  WindowStats stats;
  WindowOptions options;
  const Window window = TurnWindow(0.0, lost, options, &stats);
  EXPECT_EQ(window.samples, 0);  // no window
  EXPECT_EQ(stats.turns_dropped_for_gaps, 1);
  EXPECT_NEAR(stats.longest_gap_s, 0.1, 1e-7);  // stamps near 1.7e9 s hold 2.4e-7 s
  const std::string note = TimeStampNote(stats);
  EXPECT_NE(note.find("1 turn dropped for a gap longer than 0.05 s"), std::string::npos) << note;
  options.max_turn_gap_s = 0.2;
  const Window kept = TurnWindow(0.0, lost, options, &stats);
  EXPECT_EQ(kept.lost_samples, 10);
  EXPECT_EQ(stats.turns_dropped_for_gaps, 0);
}

TEST(Saturation, AGivenFullScaleLeavesOutPartlyClippedWindowsTooAndANoiseFreeRunIsNotJudged) {
  const SensorModel truth = testing::RandomMemsModel(2026);
  const std::vector<TableSegment> plan = SixPositionPlan();
  const std::vector<Window> all = Simulate(MemsNoise(17), plan, truth);
  // A full scale just above the fast rates' means: only their noise peaks clip, so no output is
  // pinned and only the given full scale finds them (each clipped sample biases the mean).
  double fast_mean = 0.0;
  for (const Window& w : all) {
    if (std::abs(plan[w.segment].rate_radps) > 200.0 * kDegToRad)
      fast_mean = std::max(fast_mean, w.gyro_mean.cwiseAbs().maxCoeff());
  }
  SimulationOptions clipped = MemsNoise(17);
  clipped.gyro_full_scale_raw = std::round(fast_mean + 1.0);
  WindowBuilder blind(WindowOptions(), plan);
  WindowOptions told;
  told.gyro_full_scale_raw = clipped.gyro_full_scale_raw;
  WindowBuilder builder(told, plan);
  SimulateRun(clipped, Site(), plan, truth, [&](const Sample& raw, const SegmentTruth&) {
    blind.Add(raw);
    builder.Add(raw);
  });
  EXPECT_EQ(blind.Finish().size(), all.size());
  EXPECT_EQ(blind.stats().saturated_windows, 0);
  const std::vector<Window> windows = builder.Finish();
  EXPECT_GT(builder.stats().saturated_windows, 0);
  EXPECT_LE(builder.stats().saturated_windows, FastRateWindows(all, plan));
  EXPECT_EQ(windows.size() + builder.stats().saturated_windows, all.size());

  // Noise-free, every window's spread is zero: nothing is judged pinned (nothing could be told).
  SimulationOptions noise_free = clipped;
  noise_free.gyro_noise_density = noise_free.accel_noise_density = 0.0;
  noise_free.quantize = false;
  noise_free.gyro_full_scale_raw = kGyroFullScaleCounts;
  WindowBuilder exact(WindowOptions(), plan);
  SimulateRun(noise_free, Site(), plan, truth,
              [&](const Sample& raw, const SegmentTruth&) { exact.Add(raw); });
  EXPECT_EQ(exact.Finish().size(), all.size());
  EXPECT_EQ(exact.stats().saturated_windows, 0);
}

}  // namespace
}  // namespace imufit
