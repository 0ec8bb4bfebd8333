#include "imufit/io/station.h"

#include <cmath>

#include "imufit/io/error.h"
#include "imufit/io/run_header.h"
#include "yaml_util.h"

namespace imufit {
namespace {

// One line of text: not empty, no line break, at most kMaxStationTextBytes.
std::string Line(const yaml::Located& value) {
  const std::string text = value.String();
  if (text.empty()) value.Fail("is empty (leave the key out instead)");
  if (text.find_first_of("\r\n") != std::string::npos) value.Fail("must be one line of text");
  if (text.size() > kMaxStationTextBytes) {
    value.Fail("is " + std::to_string(text.size()) + " bytes long; at most " +
               std::to_string(kMaxStationTextBytes) + " fit on a certificate");
  }
  return text;
}

StationEquipment Equipment(const yaml::Located& node) {
  node.RejectUnknownKeys({"model", "serial"});
  StationEquipment equipment;
  if (node.Has("model")) equipment.model = Line(node["model"]);
  if (node.Has("serial")) equipment.serial = Line(node["serial"]);
  return equipment;
}

// The factor to SI of `unit`, one of the units `info` may be written in; fails naming them.
double ToSi(const yaml::Located& node, const StationInfluenceInfo& info, const std::string& unit) {
  struct Factor {
    const char* unit;
    double factor;
  };
  constexpr double kPi = 3.14159265358979323846;
  static constexpr Factor kFactors[] = {{"ppm", 1e-6},
                                        {"%", 1e-2},
                                        {"mrad", 1e-3},
                                        {"arcsec", kPi / 648000.0},
                                        {"deg", kPi / 180.0},
                                        {"m/s^2", 1.0},
                                        {"mGal", 1e-5},
                                        {"degC", 1.0},
                                        {"K", 1.0}};
  const std::string allowed = std::string(" ") + info.units + " ";
  if (allowed.find(" " + unit + " ") != std::string::npos) {
    for (const Factor& f : kFactors) {
      if (unit == f.unit) return f.factor;
    }
  }
  node.Fail(QuoteForMessage(unit) + " is not a unit of " + info.key + " (known: " + info.units + ")");
}

StationUncertainty Uncertainty(const yaml::Located& node, const StationInfluenceInfo& info) {
  node.RejectUnknownKeys({"u", "half_width", "unit", "source"});
  StationUncertainty u;
  u.influence = info.influence;
  u.key = info.key;
  if (node.Has("u") == node.Has("half_width"))
    node.Fail("give either u (a standard uncertainty) or half_width");
  u.rectangular = node.Has("half_width");
  const yaml::Located value = node[u.rectangular ? "half_width" : "u"];
  u.written = value.Double();
  if (!(u.written >= 0.0) || !std::isfinite(u.written)) value.Fail("must be a number >= 0");
  u.unit = Line(node["unit"]);
  u.u_si = u.written * ToSi(node["unit"], info, u.unit) / (u.rectangular ? std::sqrt(3.0) : 1.0);
  u.source = Line(node["source"]);
  return u;
}

std::vector<StationUncertainty> Uncertainties(const yaml::Located& node) {
  node.RequireMap();
  for (const auto& entry : node.node) {
    const std::string key = entry.first.as<std::string>();
    bool known = false;
    for (const StationInfluenceInfo& info : kStationUncertainties) known = known || key == info.key;
    if (!known) {
      std::string list;
      for (const StationInfluenceInfo& info : kStationUncertainties) {
        list += (list.empty() ? "" : ", ") + std::string(info.key);
      }
      yaml::Located{node.file, entry.first, node.key}.Fail("unknown uncertainty source " +
                                                           QuoteForMessage(key) + " (known: " + list + ")");
    }
  }
  std::vector<StationUncertainty> sources;
  for (const StationInfluenceInfo& info : kStationUncertainties) {
    if (node.Has(info.key)) sources.push_back(Uncertainty(node[info.key], info));
  }
  return sources;
}

}  // namespace

Station ReadStation(const std::string& path) {
  const YAML::Node root_node = yaml::LoadFile(path);
  const yaml::Located root{&path, root_node, ""};
  root.RejectUnknownKeys({"format", "version", "station", "station_id", "laboratory", "accreditation",
                          "location", "operator", "rate_table", "chamber", "reference_calibration_due",
                          "notes", "uncertainty"});
  root.RequireFormat("imufit-station", kStationFormatVersion);
  Station station;
  station.path = path;
  station.name = Line(root["station"]);
  if (root.Has("station_id")) station.id = Line(root["station_id"]);
  if (root.Has("laboratory")) station.laboratory = Line(root["laboratory"]);
  if (root.Has("accreditation")) station.accreditation = Line(root["accreditation"]);
  if (root.Has("location")) station.location = Line(root["location"]);
  if (root.Has("operator")) station.operator_name = Line(root["operator"]);
  if (root.Has("rate_table")) station.rate_table = Equipment(root["rate_table"]);
  if (root.Has("chamber")) station.chamber = Equipment(root["chamber"]);
  if (root.Has("reference_calibration_due")) {
    const yaml::Located due = root["reference_calibration_due"];
    station.reference_calibration_due = Line(due);
    if (!IsIsoDate(station.reference_calibration_due)) {
      due.Fail(QuoteForMessage(station.reference_calibration_due) + " is not a date written YYYY-MM-DD");
    }
  }
  if (root.Has("notes")) station.notes = Line(root["notes"]);
  if (root.Has("uncertainty")) station.uncertainty = Uncertainties(root["uncertainty"]);
  return station;
}

}  // namespace imufit
