// Tests of run/segmentation.h: a plan's segments found in unlabelled runs with a known truth.
//
// Simulated runs (soaks, a ramp, rate segments, noise, quantised counts, jittered time stamps,
// raw axes of either sign) and hand sessions made here (rests, moves and turns through a known
// angle, integrated step by step) are labelled by MotionDetector + MatchPlan + Labeller and
// compared with the true labels: most samples of every dwell get their segment, no sample gets a
// wrong one, every turning sample belongs to its turn. Plans that disagree with the log (missing,
// extra, reordered segments, a wrong sign) are refused with the time of the disagreement.
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "imufit/model/constants.h"
#include "imufit/run/segmentation.h"
#include "imufit/sim/simulator.h"
#include "test_models.h"

namespace imufit {
namespace {

// A dwell of 5 s loses about half a window (0.5 s) at each end to the centred variance window;
// at least this fraction of the truly labelled samples must get their label (worst case).
constexpr double kMinLabelledFraction = 0.7;

TableSite Site() {
  TableSite site;
  site.gravity_mps2 = kStandardGravityMps2;
  site.latitude_rad = 45.0 * kDegToRad;
  return site;
}

TableSegment Static(int id, const Eigen::Vector3d& up) {
  TableSegment segment;
  segment.id = id;
  segment.up = up.normalized();
  return segment;
}

TableSegment Rate(int id, const Eigen::Vector3d& up, double rate_dps) {
  TableSegment segment = Static(id, up);
  segment.rate_radps = rate_dps * kDegToRad;
  return segment;
}

TableSegment Turn(int id, const Eigen::Vector3d& up, const Eigen::Vector3d& axis, double angle_deg) {
  TableSegment segment = Static(id, up);
  segment.angle_rad = angle_deg * kDegToRad;
  segment.axis = axis.normalized();
  return segment;
}

// Six faces, then +-50 and +-200 deg/s about x and z (ids 11..).
std::vector<TableSegment> FacesAndRates(bool with_rates = true) {
  std::vector<TableSegment> plan = {
      Static(1, Eigen::Vector3d::UnitZ()), Static(2, -Eigen::Vector3d::UnitZ()),
      Static(3, Eigen::Vector3d::UnitX()), Static(4, -Eigen::Vector3d::UnitX()),
      Static(5, Eigen::Vector3d::UnitY()), Static(6, -Eigen::Vector3d::UnitY())};
  if (!with_rates) return plan;
  int id = 11;
  for (const Eigen::Vector3d& up : {Eigen::Vector3d::UnitZ().eval(), Eigen::Vector3d::UnitX().eval()}) {
    for (double rate_dps : {50.0, -50.0, 200.0, -200.0}) plan.push_back(Rate(id++, up, rate_dps));
  }
  return plan;
}

struct LabelledRun {
  std::vector<Sample> samples;  // segment = -1: unlabelled
  std::vector<int> truth;       // the true label of each sample
};

LabelledRun Simulate(const SimulationOptions& options, const std::vector<TableSegment>& plan,
                     const SensorModel& model) {
  LabelledRun run;
  SimulateRun(options, Site(), plan, model, [&](const Sample& raw, const SegmentTruth&) {
    run.truth.push_back(raw.segment);
    run.samples.push_back(raw);
    run.samples.back().segment = kTransitionSegment;
  });
  return run;
}

Segmentation Segment(const LabelledRun& run, const std::vector<TableSegment>& plan,
                     const SegmentationOptions& options = SegmentationOptions()) {
  MotionDetector detector(options);
  for (const Sample& sample : run.samples) detector.Add(sample);
  return MatchPlan(detector.Finish(), plan, options);
}

struct Agreement {
  long long truly_labelled = 0;
  long long correct = 0;
  long long wrong = 0;  // labelled with a segment other than the true one (or while moving)
  double Fraction() const { return truly_labelled > 0 ? double(correct) / double(truly_labelled) : 0.0; }
};

Agreement Compare(const LabelledRun& run, const Segmentation& segmentation) {
  Labeller labeller(segmentation);
  Agreement agreement;
  for (size_t i = 0; i < run.samples.size(); ++i) {
    const int label = labeller.Label(run.samples[i].time_s);
    if (run.truth[i] != kTransitionSegment) ++agreement.truly_labelled;
    if (label != kTransitionSegment && label == run.truth[i]) ++agreement.correct;
    if (label != kTransitionSegment && label != run.truth[i]) ++agreement.wrong;
  }
  return agreement;
}

SimulationOptions NoisyMems() {
  SimulationOptions options;
  options.rate_hz = 100.0;
  options.dwell_s = 5.0;
  options.transition_s = 1.5;
  options.gyro_noise_density = 3e-4;
  options.accel_noise_density = 3e-3;
  options.gyro_bias_instability = 2e-4;
  options.accel_bias_instability = 2e-4;
  options.quantize = true;
  options.seed = 7;
  return options;
}

TEST(Segmentation, FindsEverySegmentOfASoakWithJitteredTimes) {
  SimulationOptions options = NoisyMems();
  options.soak_temps_c = {-20.0, 25.0, 70.0};
  options.time_jitter_s = 0.004;
  const std::vector<TableSegment> plan = FacesAndRates();
  const LabelledRun run = Simulate(options, plan, testing::RandomMemsModel(3));
  const Segmentation segmentation = Segment(run, plan);
  EXPECT_EQ(segmentation.passes, 3);
  ASSERT_EQ(segmentation.matches.size(), 3 * plan.size());
  for (size_t i = 0; i < segmentation.matches.size(); ++i) {
    EXPECT_EQ(segmentation.matches[i].segment, plan[i % plan.size()].id);
    EXPECT_EQ(segmentation.matches[i].pass, static_cast<int>(i / plan.size()));
  }
  const Agreement agreement = Compare(run, segmentation);
  EXPECT_GE(agreement.Fraction(), kMinLabelledFraction);
  EXPECT_EQ(agreement.wrong, 0);
}

TEST(Segmentation, FollowsARampThroughManyPasses) {
  SimulationOptions options = NoisyMems();
  options.ramp = true;
  options.ramp_from_c = -40.0;
  options.ramp_to_c = 85.0;
  options.passes = 4;
  options.seed = 11;
  const std::vector<TableSegment> plan = FacesAndRates();
  const LabelledRun run = Simulate(options, plan, testing::RandomMemsModel(5));
  const Segmentation segmentation = Segment(run, plan);
  EXPECT_EQ(segmentation.passes, 4);
  EXPECT_EQ(segmentation.matches.size(), 4 * plan.size());
  const Agreement agreement = Compare(run, segmentation);
  EXPECT_GE(agreement.Fraction(), kMinLabelledFraction);
  EXPECT_EQ(agreement.wrong, 0);
}

TEST(Segmentation, StaticOnlyPlanNoiselessAndSlowLogs) {
  const std::vector<TableSegment> plan = FacesAndRates(false);
  for (const bool noisy : {false, true}) {
    SimulationOptions options = noisy ? NoisyMems() : SimulationOptions();
    options.soak_temps_c = {10.0, 40.0};
    options.dwell_s = noisy ? 8.0 : 5.0;
    options.transition_s = 2.0;
    options.rate_hz = noisy ? 10.0 : 200.0;  // 10 Hz: the window widens to 16 samples
    const LabelledRun run = Simulate(options, plan, testing::RandomMemsModel(8));
    const Segmentation segmentation = Segment(run, plan);
    EXPECT_EQ(segmentation.matches.size(), 2 * plan.size()) << (noisy ? "noisy, 10 Hz" : "noiseless");
    const Agreement agreement = Compare(run, segmentation);
    EXPECT_GE(agreement.Fraction(), noisy ? 0.6 : kMinLabelledFraction)
        << (noisy ? "noisy, 10 Hz" : "noiseless");
    EXPECT_EQ(agreement.wrong, 0);
  }
}

TEST(Segmentation, RawAxesOfEitherSign) {
  SensorModel model = testing::RandomMemsModel(9);
  for (int k = 0; k < kPolynomialTerms; ++k) {
    model.accel[(kScaleCoefficient + 0) * kPolynomialTerms + k] *= -1.0;  // accel x reads backwards
    model.gyro[(kScaleCoefficient + 2) * kPolynomialTerms + k] *= -1.0;   // gyro z turns the other way
  }
  SimulationOptions options = NoisyMems();
  const std::vector<TableSegment> plan = FacesAndRates();
  const LabelledRun run = Simulate(options, plan, model);
  const Segmentation segmentation = Segment(run, plan);
  EXPECT_EQ(segmentation.accel_signs, Eigen::Vector3d(-1, 1, 1));
  EXPECT_EQ(segmentation.gyro_signs, Eigen::Vector3d(1, 1, -1));
  const Agreement agreement = Compare(run, segmentation);
  EXPECT_GE(agreement.Fraction(), kMinLabelledFraction);
  EXPECT_EQ(agreement.wrong, 0);
}

// The log of FacesAndRates() (two passes) against plans that disagree with it.
class Disagreement : public ::testing::Test {
 protected:
  void SetUp() override {
    SimulationOptions options = NoisyMems();
    options.soak_temps_c = {0.0, 50.0};
    run_ = Simulate(options, FacesAndRates(), testing::RandomMemsModel(4));
  }
  // The message of the refusal ("" if the plan was accepted).
  std::string Refusal(const std::vector<TableSegment>& plan) {
    try {
      Segment(run_, plan);
    } catch (const PlanMismatchError& e) {
      return e.what();
    }
    return "";
  }
  LabelledRun run_;
};

// The time in "at t = 12.34 .. 15.00 s" of a refusal (NaN when there is none).
double TimeOf(const std::string& message) {
  const size_t at = message.find("at t = ");
  return at == std::string::npos ? std::nan("") : std::stod(message.substr(at + 7));
}

TEST_F(Disagreement, APlanWithoutASegmentTheLogHas) {
  std::vector<TableSegment> plan = FacesAndRates();
  plan.erase(plan.begin() + 3);  // -x, at 19.5 .. 24.5 s in the log
  const std::string message = Refusal(plan);
  EXPECT_NEAR(TimeOf(message), 20.0, 0.5) << message;
  EXPECT_NE(message.find("segment 5 (pass 1: static"), std::string::npos) << message;
}

TEST_F(Disagreement, APlanWithASegmentTheLogLacks) {
  std::vector<TableSegment> plan = FacesAndRates();
  plan.insert(plan.begin() + 2, Static(40, Eigen::Vector3d(1, 1, 0)));
  const std::string message = Refusal(plan);
  EXPECT_NE(message.find("segment 40"), std::string::npos) << message;
  EXPECT_NEAR(TimeOf(message), 13.5, 0.5) << message;  // +x, 13 .. 18 s
}

TEST_F(Disagreement, SegmentsInAnotherOrder) {
  std::vector<TableSegment> plan = FacesAndRates();
  std::swap(plan[2], plan[4]);  // +y before -x before +x
  const std::string message = Refusal(plan);
  EXPECT_NEAR(TimeOf(message), 13.5, 0.5) << message;
  EXPECT_NE(message.find("missing, extra or out of order"), std::string::npos) << message;
}

TEST_F(Disagreement, ARateOfTheWrongSizeOrSign) {
  std::vector<TableSegment> plan = FacesAndRates();
  plan[8].rate_radps *= 4.0;  // +200 -> +800 deg/s, out of proportion with the others
  EXPECT_NE(Refusal(plan).find("out of proportion"), std::string::npos) << Refusal(plan);
  plan = FacesAndRates();
  std::swap(plan[6], plan[7]);  // -50 before +50 (a sign pattern alone cannot explain it: z rates both ways)
  EXPECT_NE(Refusal(plan).find("constant rate"), std::string::npos) << Refusal(plan);
}

TEST(Segmentation, ALogThatEndsInsideAPass) {
  const LabelledRun run = Simulate(NoisyMems(), FacesAndRates(), testing::RandomMemsModel(4));
  std::vector<TableSegment> plan = FacesAndRates();
  plan.push_back(Static(50, Eigen::Vector3d::UnitZ()));  // the pass should end with +z again
  try {
    Segment(run, plan);
    ADD_FAILURE() << "a log without the plan's last segment was accepted";
  } catch (const PlanMismatchError& e) {
    EXPECT_NE(std::string(e.what()).find("the run ends"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("segment 50"), std::string::npos) << e.what();
  }
}

// A hand session made here: rests, moves between faces and turns through known angles, integrated
// in small steps (d(up)/dt = -omega x up), with white noise, in counts of a unit with the given raw
// axis signs. Samples at `rate_hz` with jittered times.
class HandSession {
 public:
  HandSession(const Eigen::Vector3d& accel_signs, const Eigen::Vector3d& gyro_signs, std::uint64_t seed)
      : accel_signs_(accel_signs), gyro_signs_(gyro_signs), engine_(seed) {}

  void Rest(double seconds, int label) { Move(Eigen::Vector3d::UnitZ(), 0.0, seconds, label); }
  // Turns the body by angle_deg about the body axis `axis` with a smooth profile.
  void Move(const Eigen::Vector3d& axis, double angle_deg, double seconds, int label) {
    const long long n = std::llround(seconds * kRateHz);
    for (long long i = 0; i < n; ++i) {
      const double u = (static_cast<double>(i) + 0.5) / static_cast<double>(n);
      const double rate = angle_deg * kDegToRad * 6.0 * u * (1.0 - u) / seconds;  // d/dt of the smoothstep
      const Eigen::Vector3d omega = rate * axis.normalized();
      for (int step = 0; step < kSubSteps; ++step) {
        up_ -= omega.cross(up_) * (1.0 / kRateHz / kSubSteps);
        up_.normalize();
      }
      Sample sample;
      sample.time_s = static_cast<double>(run_.samples.size()) / kRateHz + jitter_(engine_);
      sample.temp_c = 22.0;
      sample.gyro = gyro_signs_.cwiseProduct(kGyroScale * (omega + kGyroNoise * Normal3())) + kGyroBias;
      sample.accel =
          (accel_signs_.cwiseProduct(kAccelScale * (9.80665 * up_ + kAccelNoise * Normal3())) + kAccelBias)
              .array()
              .round();
      sample.gyro = sample.gyro.array().round();
      run_.samples.push_back(sample);
      run_.truth.push_back(label);
    }
  }
  const Eigen::Vector3d& up() const { return up_; }
  const LabelledRun& run() const { return run_; }

  static constexpr double kRateHz = 100.0;

 private:
  static constexpr int kSubSteps = 20;
  static constexpr double kGyroScale = 939.65;  // raw per rad/s
  static constexpr double kAccelScale = 208.8;  // raw per m/s^2
  static constexpr double kGyroNoise = 2e-3;    // rad/s per sample
  static constexpr double kAccelNoise = 0.02;   // m/s^2 per sample
  inline static const Eigen::Vector3d kGyroBias{15.0, -22.0, 9.0};
  inline static const Eigen::Vector3d kAccelBias{40.0, -25.0, 61.0};
  Eigen::Vector3d Normal3() { return Eigen::Vector3d(normal_(engine_), normal_(engine_), normal_(engine_)); }

  Eigen::Vector3d accel_signs_;
  Eigen::Vector3d gyro_signs_;
  std::mt19937_64 engine_;
  std::normal_distribution<double> normal_;
  std::uniform_real_distribution<double> jitter_{-0.003, 0.003};
  Eigen::Vector3d up_ = Eigen::Vector3d::UnitZ();
  LabelledRun run_;
};

// Six faces then 360 deg about x, y and z and 90 deg about x, by hand: the plan, and the session.
std::vector<TableSegment> SixFacesThreeTurnsPlan() {
  std::vector<TableSegment> plan = FacesAndRates(false);
  plan.push_back(Turn(7, Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX(), 360.0));
  plan.push_back(Turn(8, Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitY(), -360.0));
  plan.push_back(Turn(9, Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitZ(), 360.0));
  plan.push_back(Turn(10, Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX(), 90.0));
  return plan;
}

LabelledRun HandRun(const Eigen::Vector3d& accel_signs, const Eigen::Vector3d& gyro_signs, std::uint64_t seed,
                    bool quarter_turn = true) {
  HandSession hand(accel_signs, gyro_signs, seed);
  // Faces: +z, -z, +x, -x, +y, -y (each move: the body turns so that gravity goes to the next face).
  const Eigen::Vector3d faces[6] = {Eigen::Vector3d::UnitZ(), -Eigen::Vector3d::UnitZ(),
                                    Eigen::Vector3d::UnitX(), -Eigen::Vector3d::UnitX(),
                                    Eigen::Vector3d::UnitY(), -Eigen::Vector3d::UnitY()};
  for (int f = 0; f < 6; ++f) {
    if (f > 0) {
      const Eigen::Vector3d from = hand.up();
      Eigen::Vector3d axis = faces[f].cross(from);
      if (axis.norm() < 1e-6) axis = from.unitOrthogonal();
      const double angle = std::atan2(from.cross(faces[f]).norm(), from.dot(faces[f])) / kDegToRad;
      hand.Move(axis.normalized(), angle, 2.0, kTransitionSegment);
    }
    hand.Rest(6.0, f + 1);
  }
  hand.Move(Eigen::Vector3d::UnitX(), 90.0, 2.0, kTransitionSegment);  // -y up -> +z up
  hand.Rest(3.0, kTransitionSegment);
  hand.Move(Eigen::Vector3d::UnitX(), 360.0, 4.0, 7);
  hand.Rest(3.0, kTransitionSegment);
  hand.Move(Eigen::Vector3d::UnitY(), -360.0, 4.0, 8);
  hand.Rest(3.0, kTransitionSegment);
  hand.Move(Eigen::Vector3d::UnitZ(), 360.0, 4.0, 9);
  hand.Rest(3.0, kTransitionSegment);
  if (quarter_turn) {
    hand.Move(Eigen::Vector3d::UnitX(), 90.0, 2.0, 10);
    hand.Rest(3.0, kTransitionSegment);
  }
  return hand.run();
}

TEST(Segmentation, HandSessionWithTurnsThroughKnownAngles) {
  const std::vector<TableSegment> plan = SixFacesThreeTurnsPlan();
  for (const auto& [accel_signs, gyro_signs] :
       {std::pair{Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(1, 1, 1)},
        std::pair{Eigen::Vector3d(1, -1, 1), Eigen::Vector3d(-1, 1, 1)}}) {
    const LabelledRun run = HandRun(accel_signs, gyro_signs, 21);
    const Segmentation segmentation = Segment(run, plan);
    ASSERT_EQ(segmentation.matches.size(), plan.size());
    EXPECT_EQ(segmentation.accel_signs, accel_signs);
    EXPECT_EQ(segmentation.gyro_signs, gyro_signs);
    // Every turning sample is in its turn's occurrence (the integral is whole); rests are never
    // labelled with another segment; a turn's label reaches a little way into the rests.
    Labeller labeller(segmentation);
    long long static_correct = 0;
    long long static_total = 0;
    for (size_t i = 0; i < run.samples.size(); ++i) {
      const int label = labeller.Label(run.samples[i].time_s);
      const int truth = run.truth[i];
      if (truth >= 7) {
        EXPECT_EQ(label, truth) << "turning sample at t = " << run.samples[i].time_s;
      }
      if (truth >= 1 && truth <= 6) {
        ++static_total;
        static_correct += label == truth;
        EXPECT_TRUE(label == truth || label == kTransitionSegment) << "t = " << run.samples[i].time_s;
      }
      if (label >= 1 && label <= 6) {
        EXPECT_EQ(label, truth) << "t = " << run.samples[i].time_s;
      }
    }
    EXPECT_GE(static_cast<double>(static_correct) / static_total, kMinLabelledFraction);
    for (const SegmentMatch& match : segmentation.matches) {
      if (match.kind != "turn") continue;
      // The detected turn spans the true one plus at most the turn margin and a window each side.
      double true_start = 1e9;
      double true_end = -1e9;
      for (size_t i = 0; i < run.samples.size(); ++i) {
        if (run.truth[i] != match.segment) continue;
        true_start = std::min(true_start, run.samples[i].time_s);
        true_end = std::max(true_end, run.samples[i].time_s);
      }
      EXPECT_LE(match.start_s, true_start);
      EXPECT_GE(match.end_s, true_end);
      const double reach_s = SegmentationOptions().turn_margin_s + SegmentationOptions().window_s;
      EXPECT_GE(match.start_s, true_start - reach_s);
      EXPECT_LE(match.end_s, true_end + reach_s);
    }
  }
}

TEST(Segmentation, ALogThatEndsAtRestAfterItsLastTurn) {
  // The rest after turn 9 has gravity along +z, as segment 1 does: it is the turn's settling, not
  // the start of another pass.
  const LabelledRun run =
      HandRun(Eigen::Vector3d::Ones(), Eigen::Vector3d::Ones(), 23, /*quarter_turn=*/false);
  std::vector<TableSegment> plan = SixFacesThreeTurnsPlan();
  plan.pop_back();
  const Segmentation segmentation = Segment(run, plan);
  EXPECT_EQ(segmentation.passes, 1);
  ASSERT_EQ(segmentation.matches.size(), plan.size());
  EXPECT_EQ(segmentation.matches.back().segment, 9);
  EXPECT_EQ(segmentation.matches.back().kind, "turn");
}

TEST(Segmentation, TurnsThatDisagreeWithThePlan) {
  const LabelledRun run = HandRun(Eigen::Vector3d::Ones(), Eigen::Vector3d::Ones(), 22);
  std::vector<TableSegment> plan = SixFacesThreeTurnsPlan();
  plan[7].axis = Eigen::Vector3d::UnitX();  // the log turns about y there
  try {
    Segment(run, plan);
    ADD_FAILURE() << "a turn about the wrong axis was accepted";
  } catch (const PlanMismatchError& e) {
    EXPECT_NE(std::string(e.what()).find("segment 8"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("turned about body"), std::string::npos) << e.what();
  }
  plan = SixFacesThreeTurnsPlan();
  plan.pop_back();  // the last 90 deg turn is not in the plan: gravity ends along +y, an extra rest
  EXPECT_THROW(Segment(run, plan), PlanMismatchError);
}

TEST(Segmentation, OptionsAreChecked) {
  SegmentationOptions options;
  EXPECT_EQ(options.Validate(), "");
  options.direction_tolerance_deg = 95.0;
  EXPECT_NE(options.Validate(), "");
  options = SegmentationOptions();
  options.noise_quantile = 1.0;
  EXPECT_NE(options.Validate(), "");
}

}  // namespace
}  // namespace imufit
