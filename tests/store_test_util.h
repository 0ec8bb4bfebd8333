// What the store tests share: the backend under test (store_test --backend ...), a fresh store on
// it per test, and fits to record.
#ifndef IMUFIT_TESTS_STORE_TEST_UTIL_H_
#define IMUFIT_TESTS_STORE_TEST_UTIL_H_

#include <string>
#include <vector>

#include "imufit/store/store.h"

namespace imufit {

// "sqlite" or "postgresql".
const std::string& StoreBackend();
// An empty store on the backend under test: an SQLite file in a fresh folder, or a new database
// in the test cluster (its libpq connection string). `name` is unique per test.
std::string FreshStore(const std::string& name);
// An empty SQLite store in a fresh folder, whatever the backend under test (a station's).
std::string FreshSqliteStore(const std::string& name);
// A fitted unit of `lot` at station "station-1", part number "IMU-9", with two figures
// (gyro_bias_dps.x = bias_dps, sigma 0.01; gyro_bias_dps.y = 0).
StoredFit MakeFit(const std::string& serial, const std::string& lot, const std::string& time_utc,
                  double bias_dps, const std::string& verdict);
// `fit` recorded at `station`.
StoredFit AtStation(StoredFit fit, const std::string& station);
// A store of known content on the backend under test (`name` unique per test): two stations, two
// lots, three months. SN2 fails at station-1 in January and passes a new run at station-2 in March
// (its latest fit); SN5 cannot be fitted.
//   station-1: SN1 lot-a 2026-01-05 PASS 1.0; SN2 lot-a 2026-01-06 FAIL 3.0
//   station-2: SN3 lot-a 2026-02-01 PASS 1.5; SN4 lot-b 2026-02-10 PASS 2.0;
//              SN5 lot-b 2026-03-01 not fitted; SN2 lot-a 2026-03-02 PASS 1.2
std::string KnownStore(const std::string& name);
// Two stations' SQLite stores, one with a fit the other has too (the same run uploaded twice).
std::vector<std::string> TwoStationStores();
// A store as imufit wrote it before the schema had runs and units (version 1): three fits, SN1 in
// lot-a twice (PASS then FAIL), SN2 in lot-a once; the FAIL fit has two figures.
void WriteVersion1Store(const std::string& path);

}  // namespace imufit

#endif  // IMUFIT_TESTS_STORE_TEST_UTIL_H_
