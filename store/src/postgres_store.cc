// The PostgreSQL backend of the results store (libpq): one connection, statements with
// parameters sent as text, schema creation and migration under an advisory lock so that shards
// opening the same database at once create it once.
#include <libpq-fe.h>

#include <cstdio>
#include <cstdlib>
#include <memory>

#include "imufit/io/error.h"
#include "imufit/store/store.h"
#include "sql_connection.h"

namespace imufit {
namespace {

// Any number: the advisory lock every imufit store takes around schema changes.
constexpr int64_t kSchemaLockKey = 0x696d7566697432;

// "?1" -> "$1": the statements are written once for both backends.
std::string ToPostgresParameters(const std::string& sql) {
  std::string out = sql;
  for (size_t i = 0; i + 1 < out.size(); ++i) {
    if (out[i] == '?' && out[i + 1] >= '0' && out[i + 1] <= '9') out[i] = '$';
  }
  return out;
}

std::string ParameterText(const SqlValue& value) {
  if (const std::string* text = std::get_if<std::string>(&value)) return *text;
  if (const int64_t* integer = std::get_if<int64_t>(&value)) return std::to_string(*integer);
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.17g", std::get<double>(value));  // round-trips exactly
  return buffer;
}

class PostgresRow : public SqlRow {
 public:
  PostgresRow(const PGresult* result, int row) : result_(result), row_(row) {}
  std::string Text(int column) const override { return PQgetvalue(result_, row_, column); }
  double Double(int column) const override { return std::strtod(PQgetvalue(result_, row_, column), nullptr); }
  int64_t Integer(int column) const override {
    return std::strtoll(PQgetvalue(result_, row_, column), nullptr, 10);
  }

 private:
  const PGresult* result_;
  int row_;
};

using Result = std::unique_ptr<PGresult, decltype(&PQclear)>;

// What errors name: database, host and user from the connection string (never a password).
std::string DisplayName(const PQconninfoOption* options, const std::string& target) {
  std::string database, host;
  for (const PQconninfoOption* o = options; o && o->keyword; ++o) {
    if (!o->val) continue;
    if (std::string(o->keyword) == "dbname") database = o->val;
    if (std::string(o->keyword) == "host") host = o->val;
  }
  if (database.empty() && host.empty()) return target;
  return "postgresql database " + (database.empty() ? std::string("(default)") : database) +
         (host.empty() ? "" : " on " + host);
}

class PostgresConnection : public SqlConnection {
 public:
  explicit PostgresConnection(const std::string& target) {
    char* error = nullptr;
    PQconninfoOption* options = PQconninfoParse(target.c_str(), &error);
    if (!options) {
      const std::string message = error ? error : "out of memory";
      PQfreemem(error);
      throw InputError("results store", "not a PostgreSQL connection string: " + message);
    }
    name_ = DisplayName(options, target);
    bool has_password = false;
    for (const PQconninfoOption* o = options; o->keyword; ++o) {
      if (std::string(o->keyword) == "password" && o->val && *o->val) has_password = true;
    }
    PQconninfoFree(options);
    if (has_password) {
      throw InputError(name_, "a password on the command line is refused: put it in ~/.pgpass or PGPASSFILE");
    }
    connection_ = PQconnectdb(target.c_str());
    if (PQstatus(connection_) != CONNECTION_OK) {
      const std::string message = PQerrorMessage(connection_);
      PQfinish(connection_);
      throw InputError(name_, "cannot connect to the results store: " + Trimmed(message));
    }
    Execute("SET client_min_messages = warning");
  }
  ~PostgresConnection() override { PQfinish(connection_); }

  const std::string& name() const override { return name_; }
  const char* backend() const override { return "postgresql"; }
  const char* AutoIdType() const override { return "BIGINT GENERATED ALWAYS AS IDENTITY PRIMARY KEY"; }
  const char* TextType() const override { return "TEXT COLLATE \"C\""; }

  void Execute(const std::string& sql) override { Check(Result(PQexec(connection_, sql.c_str()), &PQclear)); }

  void Query(const std::string& sql, const std::vector<SqlValue>& parameters,
             const std::function<void(const SqlRow&)>& row) override {
    std::vector<std::string> texts;
    for (const SqlValue& value : parameters) texts.push_back(ParameterText(value));
    std::vector<const char*> values;
    for (const std::string& text : texts) values.push_back(text.c_str());
    const Result result(
        PQexecParams(connection_, ToPostgresParameters(sql).c_str(), static_cast<int>(values.size()), nullptr,
                     values.data(), nullptr, nullptr, 0),
        &PQclear);
    Check(result);
    for (int i = 0; i < PQntuples(result.get()); ++i) row(PostgresRow(result.get(), i));
  }

  void Begin(bool exclusive) override {
    Execute("BEGIN");
    if (exclusive) Execute("SELECT pg_advisory_xact_lock(" + std::to_string(kSchemaLockKey) + ")");
  }
  void Commit() override { Execute("COMMIT"); }
  void Rollback() override { PQclear(PQexec(connection_, "ROLLBACK")); }

  bool HasTable(const std::string& table) override {
    bool found = false;
    Query("SELECT to_regclass(?1) IS NOT NULL", {table},
          [&](const SqlRow& row) { found = row.Text(0) == "t"; });
    return found;
  }

 private:
  static std::string Trimmed(std::string message) {
    while (!message.empty() && (message.back() == '\n' || message.back() == ' ')) message.pop_back();
    for (char& c : message) {
      if (c == '\n') c = ' ';
    }
    return message;
  }

  void Check(const Result& result) {
    const ExecStatusType status = PQresultStatus(result.get());
    if (status == PGRES_COMMAND_OK || status == PGRES_TUPLES_OK) return;
    const std::string message = Trimmed(PQresultErrorMessage(result.get()));
    Rollback();
    throw InputError(name_, "results store: " + message);
  }

  std::string name_;
  PGconn* connection_ = nullptr;
};

}  // namespace

bool IsPostgresStore(const std::string& target) {
  if (target.rfind("postgresql://", 0) == 0 || target.rfind("postgres://", 0) == 0) return true;
  // libpq's keyword/value form: "host=... dbname=..." (an SQLite file name has no '=' in practice).
  for (const char* keyword : {"dbname=", "host=", "service="}) {
    if (target.rfind(keyword, 0) == 0 || target.find(std::string(" ") + keyword) != std::string::npos)
      return true;
  }
  return false;
}

std::unique_ptr<SqlConnection> ConnectPostgres(const std::string& target) {
  return std::make_unique<PostgresConnection>(target);
}

}  // namespace imufit
