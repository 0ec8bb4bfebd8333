// imufit — benchmark of the results store on both backends: 100,000 stored fits (10 stations, 100
// lots, 24 months, 8 key figures each), then the history queries (`imufit history`: yield by lot,
// station and month, a station's drift of a figure, a serial's calibrations, a lot's units) and
// recording one unit's fit through ResultsStore::Record (the path a batch takes), each timed.
// Targets: every query under 1 s; a recorded fit under 20 ms (the mean of kRecordSample; the
// slowest is printed too). Figures are measured and printed against the targets, never asserted.
//
// The store is filled with a few INSERT ... SELECT statements over a generated series (fast; the
// rows are what Record writes, with shorter keys), then analysed. PostgreSQL runs in a throwaway
// cluster that tests/postgres_fixture.sh starts and stops; where it cannot start, the bench says
// why and measures SQLite only.
//
// Usage: store_bench [FITS] [--keep]   (default 100000 fits; --keep leaves the SQLite file and the
// PostgreSQL cluster in place and prints where, to EXPLAIN a query on them; stop the cluster with
// tests/postgres_fixture.sh stop STATE)
#include <libpq-fe.h>
#include <sqlite3.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "imufit/base/verdict.h"
#include "imufit/factory/lot_history.h"
#include "imufit/store/store.h"

namespace {

namespace fs = std::filesystem;
using imufit::ResultsStore;

constexpr double kQueryTargetS = 1.0;
constexpr double kRecordTargetMs = 20.0;
constexpr int kRecordSample = 200;
constexpr int kFiguresPerFit = 8;

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// The fill: stations, units, runs, fits and their figures for fits 1..N, in SQL both backends
// take. Fit i: station i % 10, lot i / 1000, month i * 24 / (N + 1) from 2024-01, every 20th FAIL.
std::vector<std::string> FillStatements(int fits) {
  const std::string n = std::to_string(fits);
  const std::string series =
      "WITH RECURSIVE s(i) AS (SELECT 1 UNION ALL SELECT i + 1 FROM s WHERE i < " + n + ") ";
  const auto pad = [](const std::string& x) {  // two digits
    return "CASE WHEN " + x + " < 10 THEN '0' || " + x + " ELSE '' || " + x + " END";
  };
  const std::string month = "(i * 24 / (" + n + " + 1))";
  const std::string time = "(2024 + " + month + " / 12) || '-' || " + pad("(1 + " + month + " % 12)") +
                           " || '-' || " + pad("(1 + i % 28)") + " || 'T' || " + pad("(i % 24)") +
                           " || ':00:00Z'";
  std::string figures;
  const char* names[kFiguresPerFit][2] = {
      {"gyro_bias_dps.x", "gyro.bias.x"},  {"gyro_bias_dps.y", "gyro.bias.y"},
      {"gyro_bias_dps.z", "gyro.bias.z"},  {"accel_bias_mg.x", "accel.bias.x"},
      {"accel_bias_mg.y", "accel.bias.y"}, {"accel_bias_mg.z", "accel.bias.z"},
      {"gyro_residual_rms_dps", ""},       {"accel_residual_rms_mg", ""}};
  for (int k = 0; k < kFiguresPerFit; ++k) {
    figures += std::string(k ? " UNION ALL " : "") + "SELECT " + std::to_string(k) + " AS pos, '" +
               names[k][0] + "' AS name, '" + names[k][1] + "' AS coef";
  }
  return {
      "INSERT INTO stations (station, first_seen_utc) " + series +
          "SELECT 'station-' || i, '2024-01-01T00:00:00Z' FROM s WHERE i <= 10",
      "INSERT INTO units (serial, part_number, lot) " + series +
          "SELECT 'SN' || i, 'IMU-9', 'LOT-' || (i / 1000) FROM s",
      "INSERT INTO runs (run_key, serial, unit, lot, station, acquired_utc, plan_sha256, samples_sha256) " +
          series +
          "SELECT 'run-' || i, 'SN' || i, 'unit-' || i, 'LOT-' || (i / 1000), 'station-' || (1 + i % 10), " +
          time + ", 'p', 's' || i FROM s",
      "INSERT INTO fits (fit_key, run_key, time_utc, software, fit_options, limits_sha256, status, verdict, "
      "message, calibration_yaml) " +
          series + "SELECT 'fit-' || i, 'run-' || i, " + time +
          ", 'imufit bench', '', 'l', 'fitted', CASE WHEN i % 20 = 0 THEN 'FAIL' ELSE 'PASS' END, '', 'yaml' "
          "FROM s",
      "INSERT INTO figures (fit_id, position, name, coefficient, unit, value, sigma, expanded_u, limit_abs, "
      "outcome) "
      "SELECT f.id, k.pos, k.name, k.coef, 'deg/s', ((f.id * 7919) % 1000) / 1000.0 - 0.5, 0.01, 0.02, 5, "
      "'pass' "
      "FROM fits f CROSS JOIN (" +
          figures + ") k",
      // Every unit has one fit: its latest.
      "INSERT INTO latest_fits (lot, unit, fit_id, time_utc) SELECT r.lot, r.unit, f.id, f.time_utc FROM "
      "fits f "
      "JOIN runs r ON r.run_key = f.run_key",
      // And their figures, as recording keeps them for the lot statistics.
      "INSERT INTO latest_figures (name, lot, unit, figure_unit, value) SELECT g.name, l.lot, l.unit, "
      "g.unit, "
      "g.value FROM latest_fits l JOIN figures g ON g.fit_id = l.fit_id",
      "ANALYZE"};
}

void FillSqlite(const std::string& path, int fits) {
  sqlite3* db = nullptr;
  sqlite3_open(path.c_str(), &db);
  sqlite3_exec(db, "BEGIN", nullptr, nullptr, nullptr);
  for (const std::string& sql : FillStatements(fits)) {
    char* error = nullptr;
    if (sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &error) != SQLITE_OK) {
      std::fprintf(stderr, "store_bench: fill: %s\n", error);
      std::exit(1);
    }
  }
  sqlite3_exec(db, "COMMIT", nullptr, nullptr, nullptr);
  sqlite3_close(db);
}

void FillPostgres(const std::string& target, int fits) {
  PGconn* db = PQconnectdb(target.c_str());
  for (const std::string& sql : FillStatements(fits)) {
    PGresult* result = PQexec(db, sql.c_str());
    if (PQresultStatus(result) != PGRES_COMMAND_OK) {
      std::fprintf(stderr, "store_bench: fill: %s\n", PQresultErrorMessage(result));
      std::exit(1);
    }
    PQclear(result);
  }
  PQfinish(db);
}

void Report(const char* what, double value, double target, const char* unit) {
  std::printf("  %-44s %9.3f %s  (target < %g %s: %s)\n", what, value, unit, target, unit,
              value < target ? "met" : "MISSED");
}

// A fit as a batch records it: a new unit of the last lot at station 1, with kFiguresPerFit figures.
imufit::StoredFit NewFit(int i) {
  imufit::StoredFit fit;
  fit.serial = "NEW" + std::to_string(i);
  fit.unit = "new-" + std::to_string(i);
  fit.lot = "LOT-NEW";
  fit.station = "station-1";
  fit.time_utc = fit.acquired_utc = "2026-01-01T00:00:00Z";
  fit.software = "imufit bench";
  fit.plan_sha256 = std::string(64, 'a');
  fit.samples_sha256 = std::to_string(i) + std::string(60, 'b');
  fit.status = imufit::NameOf(imufit::kUnitStatusNames, imufit::UnitStatus::kFitted);
  fit.verdict = imufit::VerdictName(true);
  fit.calibration_yaml = std::string(4000, 'y');  // about a calibration file's size
  for (int k = 0; k < kFiguresPerFit; ++k) {
    imufit::StoredFigure g;
    g.name = "figure_" + std::to_string(k);
    g.unit = "deg/s";
    g.value = 0.001 * k;
    g.sigma = 0.01;
    g.expanded_u = 0.02;
    fit.figures.push_back(g);
  }
  return fit;
}

void Measure(const std::string& target, const char* backend) {
  ResultsStore store(target);
  std::printf("%s: %lld fits\n", backend, static_cast<long long>(store.CountFits()));
  const std::vector<std::pair<const char*, std::function<size_t()>>> queries = {
      {"yield by lot", [&] { return store.YieldBy(imufit::YieldGroup::kLot).size(); }},
      {"yield by station", [&] { return store.YieldBy(imufit::YieldGroup::kStation).size(); }},
      {"yield by month", [&] { return store.YieldBy(imufit::YieldGroup::kMonth).size(); }},
      {"drift: gyro.bias.x at station-3", [&] { return store.Trend("gyro.bias.x", "", "station-3").size(); }},
      {"every calibration of serial SN4242", [&] { return store.BySerial("SN4242").size(); }},
      {"the units of lot LOT-42 (imufit lot)", [&] { return store.LatestOfLot("LOT-42").size(); }},
      {"lots across the store (the lot page)",
       [&] { return imufit::MakeLotHistory(&store, "LOT-42", nullptr).lots.size(); }}};
  for (const auto& [what, run] : queries) {
    const auto start = std::chrono::steady_clock::now();
    const size_t rows = run();
    const std::string label = std::string(what) + " (" + std::to_string(rows) + ")";
    Report(label.c_str(), Seconds(start), kQueryTargetS, "s");
  }
  double total_ms = 0.0, slowest_ms = 0.0;
  for (int i = 0; i < kRecordSample; ++i) {
    const imufit::StoredFit fit = NewFit(i);
    const auto start = std::chrono::steady_clock::now();
    store.Record(fit);
    const double ms = 1e3 * Seconds(start);
    total_ms += ms;
    slowest_ms = std::max(slowest_ms, ms);
  }
  Report(("record one fit, mean of " + std::to_string(kRecordSample)).c_str(), total_ms / kRecordSample,
         kRecordTargetMs, "ms");
  std::printf("  %-44s %9.3f ms\n", "record one fit, slowest", slowest_ms);
}

// Runs tests/postgres_fixture.sh ACTION STATE.
bool Fixture(const char* action, const std::string& state) {
  const std::string command =
      std::string("bash '") + IMUFIT_PG_FIXTURE + "' " + action + " '" + state + "' >/dev/null";
  return std::system(command.c_str()) == 0;
}

}  // namespace

int main(int argc, char** argv) {
  const int fits = argc > 1 ? std::atoi(argv[1]) : 100000;
  const bool keep = argc > 2 && std::string(argv[2]) == "--keep";
  const fs::path folder = fs::temp_directory_path() / ("imufit_store_bench_" + std::to_string(getpid()));
  fs::create_directories(folder);
  const std::string sqlite_path = (folder / "store.db").string();
  auto start = std::chrono::steady_clock::now();
  { ResultsStore create(sqlite_path); }
  FillSqlite(sqlite_path, fits);
  std::printf("sqlite: filled in %.1f s\n", Seconds(start));
  Measure(sqlite_path, "sqlite");

  const std::string state = (folder / "pg.state").string();
  Fixture("start", state);
  std::string target;
  std::getline(std::ifstream(state), target);
  if (target.empty() || target.rfind("unavailable", 0) == 0) {
    std::printf("postgresql: not measured (%s)\n",
                target.empty() ? "the fixture wrote nothing" : target.c_str());
  } else {
    start = std::chrono::steady_clock::now();
    { ResultsStore create(target); }
    FillPostgres(target, fits);
    std::printf("postgresql: filled in %.1f s\n", Seconds(start));
    Measure(target, "postgresql");
  }
  if (keep) {
    std::printf("kept: %s, %s (state %s)\n", sqlite_path.c_str(), target.c_str(), state.c_str());
    return 0;
  }
  Fixture("stop", state);
  fs::remove_all(folder);
  return 0;
}
