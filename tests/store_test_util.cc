#include "store_test_util.h"

#include <libpq-fe.h>
#include <sqlite3.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <gtest/gtest.h>

namespace imufit {
namespace {

std::string g_backend = "sqlite";
std::string g_cluster;  // the fixture's connection string (its maintenance database)
std::filesystem::path g_folder;

// Runs `sql` on the cluster's maintenance database.
void AdminExecute(const std::string& sql) {
  PGconn* connection = PQconnectdb(g_cluster.c_str());
  if (PQstatus(connection) != CONNECTION_OK) {
    const std::string message = PQerrorMessage(connection);
    PQfinish(connection);
    throw std::runtime_error("test cluster: " + message);
  }
  PGresult* result = PQexec(connection, sql.c_str());
  const bool ok = PQresultStatus(result) == PGRES_COMMAND_OK;
  const std::string message = PQresultErrorMessage(result);
  PQclear(result);
  PQfinish(connection);
  if (!ok) throw std::runtime_error("test cluster: " + message);
}

}  // namespace

const std::string& StoreBackend() { return g_backend; }

std::string FreshSqliteStore(const std::string& name) {
  const std::filesystem::path path = g_folder / (name + ".db");
  std::filesystem::remove(path);
  return path.string();
}

std::string FreshStore(const std::string& name) {
  if (g_backend == "sqlite") return FreshSqliteStore(name);
  const std::string database = "imufit_" + name;
  AdminExecute("DROP DATABASE IF EXISTS " + database + " WITH (FORCE)");
  AdminExecute("CREATE DATABASE " + database);
  std::string target = g_cluster;
  const size_t at = target.find("dbname=postgres");
  target.replace(at, std::strlen("dbname=postgres"), "dbname=" + database);
  return target;
}

StoredFit MakeFit(const std::string& serial, const std::string& lot, const std::string& time_utc,
                  double bias_dps, const std::string& verdict) {
  StoredFit fit;
  fit.serial = serial;
  fit.unit = serial;
  fit.lot = lot;
  fit.part_number = "IMU-9";
  fit.station = "station-1";
  fit.acquired_utc = time_utc;
  fit.time_utc = time_utc;
  fit.software = "imufit test";
  fit.plan_sha256 = std::string(64, '1');
  fit.samples_sha256 = std::string(63, '2') + serial.back();
  fit.status = "fitted";
  fit.verdict = verdict;
  fit.calibration_yaml = "calibration of " + serial + "\n";
  const auto figure = [](const std::string& name, const std::string& coefficient, double value) {
    StoredFigure f;
    f.name = name;
    f.coefficient = coefficient;
    f.unit = "deg/s";
    f.value = value;
    f.sigma = 0.01;
    return f;
  };
  StoredFigure x = figure("gyro_bias_dps.x", "gyro.bias.x", bias_dps);
  x.expanded_u = 0.02;
  fit.figures = {x, figure("gyro_bias_dps.y", "gyro.bias.y", 0.0)};
  return fit;
}

StoredFit AtStation(StoredFit fit, const std::string& station) {
  fit.station = station;
  return fit;
}

std::string KnownStore(const std::string& name) {
  const std::string target = FreshStore(name);
  ResultsStore store(target);
  store.Record(AtStation(MakeFit("SN1", "lot-a", "2026-01-05T08:00:00Z", 1.0, "PASS"), "station-1"));
  store.Record(AtStation(MakeFit("SN2", "lot-a", "2026-01-06T08:00:00Z", 3.0, "FAIL"), "station-1"));
  store.Record(AtStation(MakeFit("SN3", "lot-a", "2026-02-01T08:00:00Z", 1.5, "PASS"), "station-2"));
  store.Record(AtStation(MakeFit("SN4", "lot-b", "2026-02-10T08:00:00Z", 2.0, "PASS"), "station-2"));
  StoredFit not_fitted = AtStation(MakeFit("SN5", "lot-b", "2026-03-01T08:00:00Z", 0.0, ""), "station-2");
  not_fitted.status = "not-fitted";
  not_fitted.figures.clear();
  store.Record(not_fitted);
  StoredFit rerun = AtStation(MakeFit("SN2", "lot-a", "2026-03-02T08:00:00Z", 1.2, "PASS"), "station-2");
  rerun.samples_sha256 = std::string(64, '9');  // a new run of the unit
  store.Record(rerun);
  return target;
}

std::vector<std::string> TwoStationStores() {
  const std::string a = FreshSqliteStore("station_a"), b = FreshSqliteStore("station_b");
  ResultsStore station_a(a), station_b(b);
  station_a.Record(MakeFit("SN1", "lot-m", "2026-04-01T00:00:00Z", 1.0, "PASS"));
  station_a.Record(MakeFit("SN2", "lot-m", "2026-04-01T00:01:00Z", 2.0, "FAIL"));
  station_b.Record(MakeFit("SN2", "lot-m", "2026-04-01T00:01:00Z", 2.0, "FAIL"));
  StoredFit other = MakeFit("SN3", "lot-m", "2026-04-02T00:00:00Z", 3.0, "PASS");
  other.station = "station-2";
  station_b.Record(other);
  return {a, b};
}

void WriteVersion1Store(const std::string& path) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  const char* sql = R"sql(
CREATE TABLE schema_version (version INTEGER NOT NULL);
INSERT INTO schema_version VALUES (1);
CREATE TABLE fits (
  id INTEGER PRIMARY KEY,
  serial TEXT NOT NULL, unit TEXT NOT NULL, lot TEXT NOT NULL, time_utc TEXT NOT NULL, software TEXT NOT NULL,
  plan_sha256 TEXT NOT NULL, samples_sha256 TEXT NOT NULL, limits_sha256 TEXT NOT NULL,
  status TEXT NOT NULL, verdict TEXT NOT NULL, message TEXT NOT NULL, calibration_yaml TEXT NOT NULL);
CREATE INDEX fits_serial ON fits (serial, time_utc);
CREATE INDEX fits_lot ON fits (lot, unit);
CREATE TABLE figures (
  fit_id INTEGER NOT NULL REFERENCES fits (id), name TEXT NOT NULL, coefficient TEXT NOT NULL,
  unit TEXT NOT NULL, value REAL NOT NULL, sigma REAL NOT NULL, PRIMARY KEY (fit_id, name));
INSERT INTO fits VALUES (1, 'SN1', 'u1', 'lot-a', '2026-01-01T00:00:00Z', 'imufit 0.1', 'p1', 's1', '', 'fitted',
                         'PASS', '', 'yaml 1');
INSERT INTO fits VALUES (2, 'SN2', 'u2', 'lot-a', '2026-01-01T00:01:00Z', 'imufit 0.1', 'p1', 's2', '', 'fitted',
                         'PASS', '', 'yaml 2');
INSERT INTO fits VALUES (3, 'SN1', 'u1', 'lot-a', '2026-01-02T00:00:00Z', 'imufit 0.1', 'p1', 's1', 'l1', 'fitted',
                         'FAIL', '|gyro_bias_dps.x| 9 > 2 deg/s', 'yaml 3');
INSERT INTO figures VALUES (3, 'gyro_bias_dps.x', 'gyro.bias.x', 'deg/s', 9.0, 0.25);
INSERT INTO figures VALUES (3, 'gyro_bias_dps.y', 'gyro.bias.y', 'deg/s', 0.5, 0.25);
)sql";
  EXPECT_EQ(sqlite3_exec(db, sql, nullptr, nullptr, nullptr), SQLITE_OK) << sqlite3_errmsg(db);
  sqlite3_close(db);
}

}  // namespace imufit

// store_test --backend sqlite|postgresql [--state FILE] [gtest flags]
int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  std::string state;
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::strcmp(argv[i], "--backend") == 0) imufit::g_backend = argv[i + 1];
    if (std::strcmp(argv[i], "--state") == 0) state = argv[i + 1];
  }
  if (imufit::g_backend == "postgresql") {
    std::ifstream in(state);
    std::getline(in, imufit::g_cluster);
    if (imufit::g_cluster.empty() || imufit::g_cluster.rfind("unavailable", 0) == 0) {
      std::printf("SKIP: no PostgreSQL test cluster (%s)\n",
                  imufit::g_cluster.empty() ? ("no " + state).c_str() : imufit::g_cluster.c_str());
      return 77;
    }
  }
  imufit::g_folder =
      std::filesystem::temp_directory_path() / ("imufit_store_test_" + std::to_string(getpid()));
  std::filesystem::create_directories(imufit::g_folder);
  const int status = RUN_ALL_TESTS();
  std::filesystem::remove_all(imufit::g_folder);
  return status;
}
