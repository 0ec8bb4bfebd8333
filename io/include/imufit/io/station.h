// imufit — the station file (docs/factory.md): where and by whom a unit was calibrated, for the
// certificate's identification block.
//
//   format: imufit-station
//   version: 1
//   station: "Rate table bench 2"            # required: the station's name
//   station_id: "CB-02"                      # optional, like every key below
//   location: "Building 4, room 112"
//   operator: "J. Smith"
//   rate_table: {model: "Acutronic AC1120S", serial: "RT-2291"}
//   chamber: {model: "Espec SU-262", serial: "CH-0117"}
//   reference_calibration_due: 2027-03-31    # the reference equipment's calibration, YYYY-MM-DD
//   notes: "Rate table calibrated by the national lab, certificate NL-2026-0412."
//
// Every value is one line of text (at most kMaxStationTextBytes); unknown keys, a key twice, a list
// or mapping where text belongs, an empty value and a date that is not a real YYYY-MM-DD are
// refused with file:line:column (InputError).
#ifndef IMUFIT_IO_STATION_H_
#define IMUFIT_IO_STATION_H_

#include <cstddef>
#include <string>

namespace imufit {

inline constexpr int kStationFormatVersion = 1;
// A station value is a line on a certificate, not a document.
inline constexpr size_t kMaxStationTextBytes = 500;

struct StationEquipment {
  std::string model, serial;  // "" when not given
};

struct Station {
  std::string path;
  std::string name;  // required
  std::string id, location, operator_name;
  StationEquipment rate_table, chamber;
  std::string reference_calibration_due;  // YYYY-MM-DD; "" when not given
  std::string notes;
};

Station ReadStation(const std::string& path);

}  // namespace imufit

#endif  // IMUFIT_IO_STATION_H_
