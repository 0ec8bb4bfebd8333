// The hand procedure file (hand_procedure.h).
#include "imufit/io/hand_procedure.h"

#include <cmath>
#include <string>

#include "imufit/io/error.h"
#include "imufit/io/output_file.h"
#include "imufit/io/samples.h"
#include "yaml_util.h"

namespace imufit {
namespace {

// A number of `value` within [low, high], or a located failure naming the range.
double NumberIn(const yaml::Located& value, double low, double high, const char* unit) {
  const double number = value.Double();
  if (!(number >= low && number <= high)) {
    value.Fail(FormatDouble(number) + " is outside " + FormatDouble(low) + ".." + FormatDouble(high) +
               (*unit != '\0' ? std::string(" ") + unit : std::string()));
  }
  return number;
}

int IntegerIn(const yaml::Located& value, long low, long high) {
  const long number = value.Integer();
  if (number < low || number > high) {
    value.Fail(std::to_string(number) + " is outside " + std::to_string(low) + ".." + std::to_string(high));
  }
  return static_cast<int>(number);
}

// A [least, largest] pair of angles, degrees.
std::array<double, 2> AngleRange(const yaml::Located& value, double largest) {
  const std::vector<double> pair = value.Doubles(2);
  if (!(pair[0] >= 0.0 && pair[0] <= pair[1] && pair[1] <= largest)) {
    value.Fail("give [least, largest] with 0 <= least <= largest <= " + FormatDouble(largest) + " deg");
  }
  return {pair[0], pair[1]};
}

int AxisIndex(const std::string& name) { return name == "x" ? 0 : name == "y" ? 1 : name == "z" ? 2 : -1; }

void ReadUp(const yaml::Located& up, HandProcedure* hand) {
  if (up.node.IsScalar()) {
    if (up.String() != "any") up.Fail("give any, or a list of +x, -x, +y, -y, +z, -z, corners or [x, y, z]");
    return;
  }
  if (up.Size() == 0) up.Fail("give any, or at least one direction");
  for (size_t i = 0; i < up.Size(); ++i) {
    const yaml::Located entry = up.At(i);
    if (entry.node.IsSequence()) {
      const std::vector<double> xyz = entry.Doubles(3);
      const Eigen::Vector3d v(xyz[0], xyz[1], xyz[2]);
      if (!v.allFinite() || !(v.norm() > 1e-6)) entry.Fail("a direction must be a non-zero vector");
      hand->up.push_back(v.normalized());
      continue;
    }
    const std::string name = entry.String();
    if (name == "corners") {
      for (int corner = 0; corner < 8; ++corner) {
        hand->up.push_back(
            Eigen::Vector3d(corner & 1 ? 1 : -1, corner & 2 ? 1 : -1, corner & 4 ? 1 : -1).normalized());
      }
      continue;
    }
    const int axis = name.size() == 2 ? AxisIndex(name.substr(1)) : -1;
    if (axis < 0 || (name[0] != '+' && name[0] != '-')) {
      entry.Fail("\"" + name + "\": give +x, -x, +y, -y, +z, -z, corners or [x, y, z] (the axis up)");
    }
    hand->up.push_back((name[0] == '+' ? 1.0 : -1.0) * Eigen::Vector3d::Unit(axis));
  }
}

HandProcedure ReadHandNode(const YAML::Node& root_node, const std::string& path) {
  const yaml::Located root{&path, root_node, ""};
  if (!root_node.IsMap()) throw InputError(path, "not an imufit hand procedure (expected a YAML mapping)");
  root.RejectUnknownKeys({"format", "version", "poses", "dwell_s", "turn_s", "rate_hz", "up", "tilt_deg",
                          "twist_axes", "twist_deg", "temp_c", "warmup_c", "warmup_tau_s", "bias_temp_order",
                          "scale_temp_order", "gravity_mps2", "latitude_deg", "height_m"});
  root.RequireFormat(kHandProcedureFormat, kHandProcedureFormatVersion);
  HandProcedure hand;
  hand.path = path;
  if (root.Has("poses")) hand.poses = IntegerIn(root["poses"], 9, 10000);
  if (root.Has("dwell_s")) hand.dwell_s = NumberIn(root["dwell_s"], 1.0, 36000.0, "s");
  if (root.Has("turn_s")) hand.turn_s = NumberIn(root["turn_s"], 0.1, 600.0, "s");
  if (root.Has("rate_hz")) hand.rate_hz = NumberIn(root["rate_hz"], 10.0, 10000.0, "Hz");
  if (root.Has("up")) ReadUp(root["up"], &hand);
  if (root.Has("tilt_deg")) hand.tilt_deg = AngleRange(root["tilt_deg"], 45.0);
  if (root.Has("twist_axes")) {
    const yaml::Located axes = root["twist_axes"];
    if (axes.node.IsScalar()) {
      const std::string word = axes.String();
      if (word == "none") {
        if (root.Has("twist_deg")) root["twist_deg"].Fail("twist_axes: none takes no twist_deg");
        hand.twist_deg = {0.0, 0.0};
      } else if (word != "any") {
        axes.Fail("give any, none, or a list of x, y, z");
      }
    } else {
      if (axes.Size() == 0) axes.Fail("give any, none, or at least one of x, y, z");
      for (size_t i = 0; i < axes.Size(); ++i) {
        const int axis = AxisIndex(axes.At(i).String());
        if (axis < 0) axes.At(i).Fail("give x, y or z");
        hand.twist_axes.push_back(axis);
      }
    }
  }
  if (root.Has("twist_deg")) hand.twist_deg = AngleRange(root["twist_deg"], 180.0);
  if (root.Has("temp_c"))
    hand.temp_c = NumberIn(root["temp_c"], kMinPlausibleTempC, kMaxPlausibleTempC, "degC");
  if (root.Has("warmup_c")) hand.warmup_c = NumberIn(root["warmup_c"], 0.0, 200.0, "degC");
  if (root.Has("warmup_tau_s")) hand.warmup_tau_s = NumberIn(root["warmup_tau_s"], 1.0, 1e6, "s");
  if (root.Has("bias_temp_order")) hand.bias_temp_order = IntegerIn(root["bias_temp_order"], 0, 3);
  if (root.Has("scale_temp_order")) hand.scale_temp_order = IntegerIn(root["scale_temp_order"], 0, 3);
  if (root.Has("gravity_mps2")) {
    if (root.Has("latitude_deg")) root["latitude_deg"].Fail("give gravity_mps2 or latitude_deg, not both");
    hand.gravity_mps2 = NumberIn(root["gravity_mps2"], 9.7, 9.9, "m/s^2");
  }
  if (root.Has("latitude_deg")) hand.latitude_deg = NumberIn(root["latitude_deg"], -90.0, 90.0, "deg");
  if (root.Has("height_m")) {
    if (!root.Has("latitude_deg")) root["height_m"].Fail("height_m goes with latitude_deg");
    hand.height_m = NumberIn(root["height_m"], -500.0, 10000.0, "m");
  }
  return hand;
}

}  // namespace

bool IsHandProcedureFile(const std::string& path) {
  try {
    const YAML::Node root = yaml::LoadFile(path);
    return root.IsMap() && root["format"] && root["format"].IsScalar() &&
           root["format"].Scalar() == kHandProcedureFormat;
  } catch (const std::exception&) {
    return false;
  }
}

HandProcedure ReadHandProcedure(const std::string& path) { return ReadHandNode(yaml::LoadFile(path), path); }

HandProcedure ReadHandProcedureText(const std::string& text, const std::string& name) {
  return ReadHandNode(yaml::LoadText(text, name), name);
}

}  // namespace imufit
