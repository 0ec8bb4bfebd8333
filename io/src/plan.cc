#include "imufit/io/plan.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <string>

#include "imufit/io/error.h"
#include "imufit/io/machine_text.h"
#include "imufit/io/output_file.h"
#include "imufit/io/samples.h"
#include "imufit/model/constants.h"
#include "yaml_util.h"

namespace imufit {
namespace {

// `north` may be this far from perpendicular to `up` (docs/spec.md: 1 degree).
constexpr double kNorthToleranceRad = 1.0 * kDegToRad;
// Local gravity anywhere on Earth's surface, with margin (9.76 .. 9.84 m/s^2).
constexpr double kMinGravity = 9.7;
constexpr double kMaxGravity = 9.9;

Eigen::Vector3d ReadDirection(const yaml::Located& value) {
  const std::vector<double> xyz = value.Doubles(3);
  const Eigen::Vector3d v(xyz[0], xyz[1], xyz[2]);
  if (v == Eigen::Vector3d::Zero()) value.Fail("a direction cannot be the zero vector");
  // Its length must be an ordinary number, or normalising it gives zero or nan.
  const double norm = v.norm();
  if (!std::isfinite(norm) || norm < 1e-100 || norm > 1e100) {
    char text[100];
    std::snprintf(text, sizeof text, "a direction's length must lie between 1e-100 and 1e100 (it is %g)",
                  norm);
    value.Fail(text);
  }
  return v;
}

}  // namespace

const TableSegment* Plan::Find(int id) const {
  for (const TableSegment& segment : segments) {
    if (segment.id == id) return &segment;
  }
  return nullptr;
}

namespace {

// A plan from its parsed YAML, named `path`.
Plan ReadPlanNode(const YAML::Node& root_node, const std::string& path) {
  const yaml::Located root{&path, root_node, ""};
  if (!root_node.IsMap()) throw InputError(path, "not an imufit plan (expected a YAML mapping)");
  root.RejectUnknownKeys(
      {"format", "version", "gravity_mps2", "latitude_deg", "serial", "soak_temps_c", "segments"});
  root.RequireFormat("imufit-plan", kPlanFormatVersion);
  Plan plan;
  plan.path = path;
  plan.site.gravity_mps2 = root["gravity_mps2"].Double();
  if (!(plan.site.gravity_mps2 >= kMinGravity && plan.site.gravity_mps2 <= kMaxGravity)) {
    root["gravity_mps2"].Fail("local gravity on Earth lies between 9.7 and 9.9 m/s^2");
  }
  if (root.Has("latitude_deg")) {
    const double latitude_deg = root["latitude_deg"].Double();
    if (std::abs(latitude_deg) > 90.0) root["latitude_deg"].Fail("latitude must be within [-90, 90] degrees");
    plan.site.latitude_rad = latitude_deg * kDegToRad;
  }
  if (root.Has("serial")) plan.serial = root["serial"].String();
  if (root.Has("soak_temps_c")) {
    const yaml::Located soak = root["soak_temps_c"];
    if (soak.Size() == 0) soak.Fail("soak_temps_c lists the chamber's set-points, degC: at least one");
    for (size_t i = 0; i < soak.Size(); ++i) {
      const double temp_c = soak.At(i).Double();
      if (!(temp_c >= kMinPlausibleTempC && temp_c <= kMaxPlausibleTempC)) {
        soak.At(i).Fail(FormatDouble(temp_c) + " degC is outside " + FormatDouble(kMinPlausibleTempC) + ".." +
                        FormatDouble(kMaxPlausibleTempC) + " degC (soak_temps_c is in degC)");
      }
      plan.soak_temps_c.push_back(temp_c);
    }
  }

  const yaml::Located segments = root["segments"];
  if (segments.Size() == 0) segments.Fail("a plan needs at least one segment");
  std::set<int> ids;
  for (size_t i = 0; i < segments.Size(); ++i) {
    const yaml::Located entry = segments.At(i);
    entry.RejectUnknownKeys({"id", "up", "rate_dps", "angle_deg", "axis", "north", "lever_arm_m"});
    TableSegment segment;
    const long id = entry["id"].Integer();
    if (id < 0 || id > 1000000000L) entry["id"].Fail("an id is an integer >= 0");
    segment.id = static_cast<int>(id);
    if (!ids.insert(segment.id).second) entry["id"].Fail("id " + std::to_string(id) + " repeats");
    segment.up = ReadDirection(entry["up"]).normalized();
    if (entry.Has("rate_dps")) segment.rate_radps = entry["rate_dps"].Double() * kDegToRad;
    if (entry.Has("angle_deg")) {
      if (entry.Has("rate_dps")) {
        entry["angle_deg"].Fail(
            "a turn through a known angle (angle_deg) has no rate_dps: give one or the other");
      }
      const double angle_deg = entry["angle_deg"].Double();
      if (angle_deg == 0.0)
        entry["angle_deg"].Fail("a turn's angle cannot be 0 (a static segment omits angle_deg)");
      segment.angle_rad = angle_deg * kDegToRad;
    }
    if (entry.Has("axis")) {
      if (segment.IsStatic()) {
        entry["axis"].Fail(
            "axis is the rotation axis of a rate_dps or angle_deg segment; a static segment has none");
      }
      segment.axis = ReadDirection(entry["axis"]).normalized();
    }
    if (entry.Has("lever_arm_m") && segment.IsTurn()) {
      entry["lever_arm_m"].Fail(
          "a turn (angle_deg) cannot take a lever arm: its centripetal force depends on the rate profile, "
          "which "
          "the plan does not give");
    }
    if (entry.Has("north")) {
      if (!segment.IsStatic()) {
        entry["north"].Fail(
            "north is for static segments only (in a rate or turn segment the horizontal Earth "
            "rate turns with the table)");
      }
      const Eigen::Vector3d north = ReadDirection(entry["north"]).normalized();
      if (std::abs(north.dot(segment.up)) > std::sin(kNorthToleranceRad)) {
        entry["north"].Fail("north is not horizontal: it is " +
                            std::to_string(std::asin(std::abs(north.dot(segment.up))) / kDegToRad) +
                            " degrees from perpendicular to up (at most 1 allowed)");
      }
      segment.north = (north - segment.up * north.dot(segment.up)).normalized();
    }
    if (entry.Has("lever_arm_m")) {
      const std::vector<double> r = entry["lever_arm_m"].Doubles(3);
      segment.lever_arm_m = Eigen::Vector3d(r[0], r[1], r[2]);
      // An offset from the table's axis past any rate table's (a centrifuge's arm aside) is a length
      // written in millimetres: at 300 deg/s, 12 "m" would be a specific force of 34 g.
      if (const double arm_m = segment.lever_arm_m->norm(); arm_m > kMaxLeverArmM) {
        entry["lever_arm_m"].Fail("the sensor lies " + FormatDouble(arm_m) +
                                  " m from the table's axis: " + "millimetres? lever_arm_m is in metres (" +
                                  FormatDouble(r[0] / 1000.0) + ", " + FormatDouble(r[1] / 1000.0) + ", " +
                                  FormatDouble(r[2] / 1000.0) + " if these are mm)");
      }
    }
    plan.segments.push_back(segment);
  }
  return plan;
}

}  // namespace

Plan ReadPlan(const std::string& path) { return ReadPlanNode(yaml::LoadFile(path), path); }

Plan ReadPlanText(const std::string& text, const std::string& name) {
  return ReadPlanNode(yaml::LoadText(text, name), name);
}

namespace {

MachineDoc VectorDoc(const Eigen::Vector3d& v) { return MachineDoc::Numbers({v.x(), v.y(), v.z()}); }

}  // namespace

std::string PlanYaml(const Plan& plan, const std::string& comment) {
  MachineDoc doc = MachineDoc::Map();
  size_t start = 0;
  while (!comment.empty() && start < comment.size()) {
    const size_t end = std::min(comment.find('\n', start), comment.size());
    doc.Comment(comment.substr(start, end - start));
    start = end + 1;
  }
  doc.Add("format", MachineDoc::Text("imufit-plan"));
  doc.Add("version", MachineDoc::Integer(kPlanFormatVersion));
  doc.Add("gravity_mps2", MachineDoc::Number(plan.site.gravity_mps2));
  if (plan.site.latitude_rad)
    doc.Add("latitude_deg", MachineDoc::Number(*plan.site.latitude_rad / kDegToRad));
  if (!plan.serial.empty()) doc.Add("serial", MachineDoc::Text(plan.serial));
  if (!plan.soak_temps_c.empty()) doc.Add("soak_temps_c", MachineDoc::Numbers(plan.soak_temps_c));
  MachineDoc segments = MachineDoc::List(MachineDoc::Style::kBlock);
  for (const TableSegment& s : plan.segments) {
    MachineDoc segment = MachineDoc::Map(MachineDoc::Style::kFlow);
    segment.Add("id", MachineDoc::Integer(s.id)).Add("up", VectorDoc(s.up));
    if (s.rate_radps != 0.0) segment.Add("rate_dps", MachineDoc::Number(s.rate_radps / kDegToRad));
    if (s.angle_rad) segment.Add("angle_deg", MachineDoc::Number(*s.angle_rad / kDegToRad));
    if (s.axis) segment.Add("axis", VectorDoc(*s.axis));
    if (s.north) segment.Add("north", VectorDoc(*s.north));
    if (s.lever_arm_m) segment.Add("lever_arm_m", VectorDoc(*s.lever_arm_m));
    segments.Push(std::move(segment));
  }
  doc.Add("segments", std::move(segments));
  return YamlText(doc);
}

}  // namespace imufit
