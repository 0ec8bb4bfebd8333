// What the store tests share: the backend under test (store_test --backend ...), a fresh store on
// it per test, and fits to record.
#ifndef IMUFIT_TESTS_STORE_TEST_UTIL_H_
#define IMUFIT_TESTS_STORE_TEST_UTIL_H_

#include <string>

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
// A store as imufit wrote it before the schema had runs and units (version 1): three fits, SN1 in
// lot-a twice (PASS then FAIL), SN2 in lot-a once; the FAIL fit has two figures.
void WriteVersion1Store(const std::string& path);

}  // namespace imufit

#endif  // IMUFIT_TESTS_STORE_TEST_UTIL_H_
