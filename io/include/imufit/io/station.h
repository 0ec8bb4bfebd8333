// imufit — the station file (docs/factory.md): where and by whom a unit was calibrated, for the
// certificate's identification block.
//
//   format: imufit-station
//   version: 1
//   station: "Rate table bench 2"            # required: the station's name
//   station_id: "CB-02"                      # optional, like every key below
//   laboratory: "Acme Inertial Calibration Laboratory, 12 Dock Road, Bristol"  # who issues it
//   accreditation: "UKAS 1234 (ISO/IEC 17025)"
//   location: "Building 4, room 112"
//   operator: "J. Smith"
//   rate_table: {model: "Acutronic AC1120S", serial: "RT-2291"}
//   chamber: {model: "Espec SU-262", serial: "CH-0117"}
//   reference_calibration_due: 2027-03-31    # the reference equipment's calibration, YYYY-MM-DD
//   notes: "Rate table calibrated by the national lab, certificate NL-2026-0412."
//   uncertainty:                             # Type B sources of the uncertainty budget (GUM)
//     rate_accuracy: {u: 10, unit: ppm, source: "rate table certificate NL-2026-0412"}
//     table_axis_tilt: {half_width: 20, unit: arcsec, source: "levelled to +-20 arcsec"}
//     fixture_orthogonality: {u: 0.1, unit: mrad, source: "fixture inspection report F-17"}
//     fixture_alignment: {u: 0.2, unit: mrad, source: "seating repeatability, 10 re-seats"}
//     local_gravity: {u: 2e-5, unit: m/s^2, source: "gravity survey, point 4-112"}
//     thermometer: {half_width: 0.5, unit: degC, source: "chamber sensor class A"}
//
// An uncertainty source is a standard uncertainty `u`, or the `half_width` a of a rectangular
// distribution (u = a / sqrt(3), GUM 4.3.7), in one of its units (kStationUncertainties), with the
// `source` it is taken from (required: a budget line names where its number comes from).
//
// Every value is one line of text (at most kMaxStationTextBytes); unknown keys, a key twice, a list
// or mapping where text belongs, an empty value and a date that is not a real YYYY-MM-DD are
// refused with file:line:column (InputError).
#ifndef IMUFIT_IO_STATION_H_
#define IMUFIT_IO_STATION_H_

#include <cstddef>
#include <string>
#include <vector>

namespace imufit {

inline constexpr int kStationFormatVersion = 1;
// A station value is a line on a certificate, not a document.
inline constexpr size_t kMaxStationTextBytes = 500;

// The Type B sources a station can declare, each with the units it may be written in.
enum class StationInfluence {
  kRateAccuracy,          // relative error of the table's rate
  kTableAxisTilt,         // the table's axis from the vertical (its wobble included)
  kFixtureOrthogonality,  // the fixture's faces from square
  kFixtureAlignment,      // the unit seated in the fixture
  kLocalGravity,          // the site's gravity
  kThermometer,           // the temperature reading
};

struct StationInfluenceInfo {
  StationInfluence influence;
  const char* key;    // as written in the file
  const char* title;  // for the budget's lines
  const char* units;  // the units it may be written in, space-separated; the first is the budget's
};

inline constexpr StationInfluenceInfo kStationUncertainties[] = {
    {StationInfluence::kRateAccuracy, "rate_accuracy", "Rate table rate accuracy", "ppm %"},
    {StationInfluence::kTableAxisTilt, "table_axis_tilt", "Rate table axis tilt and wobble",
     "mrad arcsec deg"},
    {StationInfluence::kFixtureOrthogonality, "fixture_orthogonality", "Fixture orthogonality",
     "mrad arcsec deg"},
    {StationInfluence::kFixtureAlignment, "fixture_alignment", "Unit alignment in the fixture",
     "mrad arcsec deg"},
    {StationInfluence::kLocalGravity, "local_gravity", "Local gravity", "m/s^2 mGal"},
    {StationInfluence::kThermometer, "thermometer", "Thermometer", "degC K"},
};

struct StationUncertainty {
  StationInfluence influence = StationInfluence::kRateAccuracy;
  std::string key;           // kStationUncertainties' key
  double written = 0.0;      // as written: u, or the half width
  std::string unit;          // as written
  bool rectangular = false;  // `half_width` given: a rectangular distribution
  // The standard uncertainty in SI: relative (rate), rad (angles), m/s^2 (gravity), degC.
  double u_si = 0.0;
  std::string source;
};

struct StationEquipment {
  std::string model, serial;  // "" when not given
};

struct Station {
  std::string path;
  std::string name;  // required
  std::string id, location, operator_name;
  // The laboratory issuing the certificate (name and address) and its accreditation; "" when not given.
  std::string laboratory, accreditation;
  StationEquipment rate_table, chamber;
  std::string reference_calibration_due;  // YYYY-MM-DD; "" when not given
  std::string notes;
  std::vector<StationUncertainty> uncertainty;  // in kStationUncertainties order; empty: none declared
};

Station ReadStation(const std::string& path);

}  // namespace imufit

#endif  // IMUFIT_IO_STATION_H_
