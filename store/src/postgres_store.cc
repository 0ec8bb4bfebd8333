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

// The password a connection string carries, as written ("" when none): after the user in a URL's
// user information (postgresql://user:PASSWORD@host/db, even when the rest of the URL is malformed),
// or a keyword/value string's password=PASSWORD (quoted or not).
std::string PasswordIn(const std::string& target) {
  const size_t scheme = target.find("://");
  if (scheme != std::string::npos) {
    const size_t start = scheme + 3;
    const size_t at = target.find('@', start);
    const size_t slash = target.find('/', start);
    if (at == std::string::npos || (slash != std::string::npos && slash < at)) return "";
    const size_t colon = target.find(':', start);
    return colon != std::string::npos && colon < at ? target.substr(colon + 1, at - colon - 1) : "";
  }
  for (size_t key = target.find("password"); key != std::string::npos;
       key = target.find("password", key + 1)) {
    if (key > 0 && target[key - 1] != ' ' && target[key - 1] != '\t') continue;
    size_t at = target.find_first_not_of(" \t", key + 8);
    if (at == std::string::npos || target[at] != '=') continue;
    at = target.find_first_not_of(" \t", at + 1);
    if (at == std::string::npos) return "";
    if (target[at] != '\'') return target.substr(at, target.find_first_of(" \t", at) - at);
    std::string value;
    for (size_t i = at + 1; i < target.size() && target[i] != '\''; ++i) {
      if (target[i] == '\\' && i + 1 < target.size()) ++i;
      value += target[i];
    }
    return value;
  }
  return "";
}

// `text` with every occurrence of the password `target` carries replaced: no message, log or
// file ever holds a password.
std::string WithoutPassword(std::string text, const std::string& target) {
  const std::string password = PasswordIn(target);
  if (password.empty()) return text;
  for (size_t at = text.find(password); at != std::string::npos; at = text.find(password, at + 3)) {
    text.replace(at, password.size(), "***");
  }
  return text;
}

// What errors name: database, host and user from the connection string (never a password).
std::string DisplayName(const PQconninfoOption* options, const std::string& target) {
  std::string database, host;
  for (const PQconninfoOption* o = options; o && o->keyword; ++o) {
    if (!o->val) continue;
    if (std::string(o->keyword) == "dbname") database = o->val;
    if (std::string(o->keyword) == "host") host = o->val;
  }
  if (database.empty() && host.empty()) return WithoutPassword(target, target);
  return "postgresql database " + (database.empty() ? std::string("(default)") : database) +
         (host.empty() ? "" : " on " + host);
}

class PostgresConnection : public SqlConnection {
 public:
  explicit PostgresConnection(const std::string& target) {
    char* error = nullptr;
    PQconninfoOption* options = PQconninfoParse(target.c_str(), &error);
    if (!options) {
      const std::string message = error ? Trimmed(error) : "out of memory";
      PQfreemem(error);
      throw InputError("results store",
                       "not a PostgreSQL connection string: " + WithoutPassword(message, target));
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
      throw InputError(name_,
                       "cannot connect to the results store: " + WithoutPassword(Trimmed(message), target));
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
    if (detached_) return Execute("SAVEPOINT imufit_step");  // inside the transaction that is never committed
    Execute("BEGIN");
    if (exclusive) Execute("SELECT pg_advisory_xact_lock(" + std::to_string(kSchemaLockKey) + ")");
  }
  void Commit() override { Execute(detached_ ? "RELEASE SAVEPOINT imufit_step" : "COMMIT"); }
  void Rollback() override {
    PQclear(PQexec(connection_, detached_ ? "ROLLBACK TO SAVEPOINT imufit_step" : "ROLLBACK"));
  }

  // A read of an older schema: the migration and every later statement run in one transaction that
  // is rolled back when the connection closes.
  void Detach() override {
    Execute("BEGIN");
    detached_ = true;
  }

  std::vector<std::string> Tables() override {
    std::vector<std::string> tables;
    Query("SELECT table_name FROM information_schema.tables WHERE table_schema = current_schema() ORDER BY 1",
          {}, [&](const SqlRow& row) { tables.push_back(row.Text(0)); });
    return tables;
  }

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
  bool detached_ = false;
};

}  // namespace

bool IsPostgresStore(const std::string& target) {
  if (target.rfind("postgresql://", 0) == 0 || target.rfind("postgres://", 0) == 0) return true;
  // libpq's keyword/value form: "host=... dbname=..." (an SQLite file name has no '=' in practice).
  for (const char* keyword : {"dbname=", "host=", "hostaddr=", "port=", "user=", "password=", "service="}) {
    if (target.rfind(keyword, 0) == 0 || target.find(std::string(" ") + keyword) != std::string::npos)
      return true;
  }
  return false;
}

std::unique_ptr<SqlConnection> ConnectPostgres(const std::string& target) {
  return std::make_unique<PostgresConnection>(target);
}

}  // namespace imufit
