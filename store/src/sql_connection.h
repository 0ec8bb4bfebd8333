// imufit — what the results store needs of a database: one connection that runs SQL with
// parameters in transactions. Two backends: SQLite (store.cc, the embedded default) and PostgreSQL
// (postgres_store.cc, libpq). ResultsStore writes its schema and queries once, in the SQL both
// accept (parameters written ?1, ?2, ...; INSERT ... ON CONFLICT; window functions).
#ifndef IMUFIT_FACTORY_SRC_SQL_CONNECTION_H_
#define IMUFIT_FACTORY_SRC_SQL_CONNECTION_H_

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <variant>
#include <vector>

#include <string>
#include <vector>

#include "imufit/store/store.h"

namespace imufit {

// A parameter: text, a finite double or an integer.
using SqlValue = std::variant<std::string, double, int64_t>;

// One row of a result, columns from 0.
class SqlRow {
 public:
  virtual ~SqlRow() = default;
  virtual std::string Text(int column) const = 0;
  virtual double Double(int column) const = 0;
  virtual int64_t Integer(int column) const = 0;
};

class SqlConnection {
 public:
  virtual ~SqlConnection() = default;
  // What errors name: the file, or the PostgreSQL database (never a password).
  virtual const std::string& name() const = 0;
  // "sqlite" or "postgresql".
  virtual const char* backend() const = 0;
  // Runs statements without parameters (several, separated by ';').
  virtual void Execute(const std::string& sql) = 0;
  // Runs one statement with parameters; calls `row` for each row it returns.
  virtual void Query(const std::string& sql, const std::vector<SqlValue>& parameters,
                     const std::function<void(const SqlRow&)>& row) = 0;
  // A write transaction; on SQLite it takes the write lock at once, on PostgreSQL it also takes
  // the store's advisory lock when `exclusive` (schema creation and migration).
  virtual void Begin(bool exclusive) = 0;
  virtual void Commit() = 0;
  virtual void Rollback() = 0;  // harmless when no transaction is open
  virtual bool HasTable(const std::string& table) = 0;
  // Every table of the database's schema (SQLite's main database; PostgreSQL's current schema),
  // imufit's or not, in name order.
  virtual std::vector<std::string> Tables() = 0;
  // Whether this connection may change the database (a read of a read-only file may not).
  virtual bool Writable() const { return true; }
  // A read that must not change the database but needs it migrated: from now on the connection
  // works on a private copy (SQLite: in memory) or inside a transaction that is never committed
  // (PostgreSQL); nothing reaches the database.
  virtual void Detach() = 0;
  // Called once the database is known to be an imufit store of the current schema: the SQLite
  // backend switches a writable file to WAL (never done to a database that is not imufit's).
  virtual void Ready() {}
  // Called in the transaction that created or migrated the schema to `version` (SQLite keeps it in
  // its user_version too).
  virtual void SchemaWritten(int /*version*/) {}
  // The column type of a primary key numbered by the database, and of text (compared bytewise).
  virtual const char* AutoIdType() const = 0;
  virtual const char* TextType() const = 0;
};

// Connects to the database IsPostgresStore() recognises; InputError naming the database when it cannot, or
// when `target` carries a password (a password belongs in ~/.pgpass or PGPASSFILE, never on a command line).
std::unique_ptr<SqlConnection> ConnectPostgres(const std::string& target);
// Opens (creating when missing) an SQLite database file; InputError naming it when it cannot.
std::unique_ptr<SqlConnection> OpenSqlite(const std::string& path, StoreAccess access);

}  // namespace imufit

#endif  // IMUFIT_FACTORY_SRC_SQL_CONNECTION_H_
