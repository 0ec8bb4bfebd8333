#include "imufit/pipeline/static_stretch.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <utility>

#include "imufit/io/error.h"
#include "imufit/io/samples.h"

namespace imufit {
namespace {

OptionTable<NoiseStretchOptions> MakeNoiseStretchOptionTable() {
  OptionTable<NoiseStretchOptions> t;
  OptionEntry<NoiseStretchOptions>& segment = t.Text(
      "noise_segment", "--noise-segment",
      "the static plan segment (its id) whose stretch the certificate measures the gyro noise on (default: "
      "of the static stretches at least 60 s long, the one whose mean temperature is nearest 25 degC)",
      [](const NoiseStretchOptions& o) { return o.segment ? std::to_string(*o.segment) : std::string(); },
      [](const std::string& text, NoiseStretchOptions* o) {
        if (text.empty()) {
          o->segment.reset();
          return std::string();
        }
        char* end = nullptr;
        const long id = std::strtol(text.c_str(), &end, 10);
        if (*end != '\0' || id < 0 || id > 1000000000L) {
          return "noise_segment " + QuoteForMessage(text) + " is not a segment id (an integer >= 0)";
        }
        o->segment = static_cast<int>(id);
        return std::string();
      });
  // Another stretch gives another certificate: in the fingerprint when set (a lot certified before
  // the option existed is not redone).
  segment.fingerprint = Fingerprint::kCustom;
  segment.describe = [](const NoiseStretchOptions& o) {
    return o.segment ? "noise_segment=" + std::to_string(*o.segment) : std::string();
  };
  return t;
}

std::string Seconds(double s) {
  char text[32];
  std::snprintf(text, sizeof text, "%.0f s", s);
  return text;
}

}  // namespace

const OptionTable<NoiseStretchOptions>& NoiseStretchOptionTable() {
  static const OptionTable<NoiseStretchOptions> table = MakeNoiseStretchOptionTable();
  return table;
}

NoiseStretchFinder::NoiseStretchFinder(const Plan& plan, const NoiseStretchOptions& options)
    : named_(options.segment) {
  // A segment id names the plan's first segment with that id (Plan::Find).
  std::set<int> seen;
  for (const TableSegment& segment : plan.segments) {
    if (seen.insert(segment.id).second && segment.IsStatic()) static_segments_.insert(segment.id);
  }
  if (!named_) return;
  const std::string id = std::to_string(*named_);
  if (plan.Find(*named_) == nullptr) {
    throw InputError(plan.path, "noise_segment: the plan has no segment " + id + " (--noise-segment)");
  }
  if (static_segments_.count(*named_) == 0) {
    throw InputError(plan.path, "noise_segment: segment " + id +
                                    " turns the table; the noise is measured on a static segment "
                                    "(--noise-segment)");
  }
  static_segments_ = {*named_};
}

void NoiseStretchFinder::Add(const Sample& sample) {
  const bool is_static = static_segments_.count(sample.segment) > 0;
  if (!is_static || (current_.size() > 0 && current_.segment != sample.segment)) Close();
  if (!is_static) return;
  if (current_.size() == 0) {
    current_.segment = sample.segment;
    current_.start_time_s = sample.time_s;
  }
  current_.end_time_s = sample.time_s;
  current_.temp_sum_c += sample.temp_c;
  for (int axis = 0; axis < 3; ++axis) current_.gyro[axis].push_back(sample.gyro(axis));
}

bool NoiseStretchFinder::Better(const StaticStretch& a, const StaticStretch& b) const {
  if (b.size() == 0) return a.size() > 0;
  const bool a_long = a.duration_s() >= kMinAllanStretchS;
  const bool b_long = b.duration_s() >= kMinAllanStretchS;
  if (named_ || !a_long || !b_long) return a_long != b_long ? a_long : a.size() > b.size();
  const double a_off = std::abs(a.mean_temp_c() - kNoiseReferenceTempC);
  const double b_off = std::abs(b.mean_temp_c() - kNoiseReferenceTempC);
  return a_off != b_off ? a_off < b_off : a.size() > b.size();
}

void NoiseStretchFinder::Close() {
  if (current_.size() == 0) return;
  ++stretches_;
  if (current_.duration_s() >= kMinAllanStretchS) ++long_ones_;
  if (Better(current_, best_)) std::swap(best_, current_);
  current_.segment = kTransitionSegment;
  current_.start_time_s = current_.end_time_s = current_.temp_sum_c = 0.0;
  for (std::vector<double>& axis : current_.gyro) axis.clear();  // keeps the memory for the next
}

StaticStretch NoiseStretchFinder::Finish() {
  Close();
  current_ = StaticStretch();
  best_.named = named_.has_value();
  if (named_) best_.segment = *named_;
  if (best_.size() == 0) return std::move(best_);
  const std::string min = Seconds(kMinAllanStretchS);
  if (named_) {
    best_.chosen = "segment " + std::to_string(*named_) + " as named (--noise-segment)";
    if (stretches_ > 1) best_.chosen += ", its longest of " + std::to_string(stretches_) + " stretches";
  } else if (long_ones_ == 0) {
    best_.chosen = "the longest static stretch; none is " + min + " long";
  } else if (long_ones_ == 1) {
    best_.chosen = "the only static stretch at least " + min + " long";
  } else {
    char reference[16];
    std::snprintf(reference, sizeof reference, "%g", kNoiseReferenceTempC);
    best_.chosen = "of the " + std::to_string(long_ones_) + " static stretches at least " + min +
                   " long, the one nearest " + reference + " degC, where data sheets quote noise";
  }
  return std::move(best_);
}

StaticStretch ReadStaticStretch(const Plan& plan, const std::string& samples_path, const SamplesInput& input,
                                const std::optional<Segmentation>& segmentation,
                                const NoiseStretchOptions& options) {
  NoiseStretchFinder stretch(plan, options);
  SamplesReader reader(samples_path, /*require_segment=*/false, input.Format());
  std::optional<Labeller> labeller;
  if (!reader.has_segment()) {
    labeller.emplace(segmentation ? *segmentation : SegmentSamplesFile(plan, samples_path, input));
  }
  Sample sample;
  while (reader.Next(&sample)) {
    if (labeller) sample.segment = labeller->Label(sample.time_s);
    stretch.Add(sample);
  }
  return stretch.Finish();
}

}  // namespace imufit
