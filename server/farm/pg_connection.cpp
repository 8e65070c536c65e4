#include "server/farm/pg_connection.h"

#include <libpq-fe.h>
#include <poll.h>

#include <cerrno>
#include <cstdlib>

namespace penumbra::server {

std::string redact_url(const std::string& url) {
  // scheme://user:password@host... : the part between the first ':' after "//" and '@'.
  const std::size_t start = url.find("//");
  const std::size_t at = url.find('@', start == std::string::npos ? 0 : start);
  if (start == std::string::npos || at == std::string::npos) return url;
  const std::size_t colon = url.find(':', start + 2);
  if (colon == std::string::npos || colon > at) return url;
  return url.substr(0, colon + 1) + "***" + url.substr(at);
}

PgRows::PgRows(PGresult* result) : result_(result) {}
PgRows::~PgRows() {
  if (result_) PQclear(result_);
}
PgRows::PgRows(PgRows&& other) noexcept : result_(other.result_) { other.result_ = nullptr; }
int PgRows::size() const { return result_ ? PQntuples(result_) : 0; }
int PgRows::column(const char* name) const {
  const int c = result_ ? PQfnumber(result_, name) : -1;
  if (c < 0) throw StoreError(std::string("no column ") + name + " in the result");
  return c;
}
std::string PgRows::value(int row, int column) const {
  return std::string(PQgetvalue(result_, row, column), std::size_t(PQgetlength(result_, row, column)));
}
bool PgRows::is_null(int row, const char* name) const {
  return PQgetisnull(result_, row, column(name)) != 0;
}
long long PgRows::int_value(int row, const char* name) const {
  if (is_null(row, name)) return 0;
  return std::strtoll(PQgetvalue(result_, row, column(name)), nullptr, 10);
}
double PgRows::double_value(int row, const char* name) const {
  if (is_null(row, name)) return 0;
  return std::strtod(PQgetvalue(result_, row, column(name)), nullptr);
}
long long PgRows::affected() const {
  const char* n = result_ ? PQcmdTuples(result_) : "";
  return *n ? std::strtoll(n, nullptr, 10) : 0;
}

PgConnection::PgConnection(std::string url) : url_(std::move(url)) { ensure_open(); }

PgConnection::~PgConnection() {
  if (conn_) PQfinish(conn_);
}

bool PgConnection::ok() const { return conn_ && PQstatus(conn_) == CONNECTION_OK; }

void PgConnection::ensure_open() {
  if (ok()) return;
  if (conn_) {
    PQfinish(conn_);
    conn_ = nullptr;
  }
  conn_ = PQconnectdb(url_.c_str());
  if (PQstatus(conn_) != CONNECTION_OK) {
    std::string why = PQerrorMessage(conn_);
    while (!why.empty() && (why.back() == '\n' || why.back() == ' ')) why.pop_back();
    PQfinish(conn_);
    conn_ = nullptr;
    throw StoreError("cannot connect to " + redact_url(url_) + ": " + why);
  }
  // Server notices (e.g. "relation already exists, skipping") stay out of the service's log.
  PQsetNoticeProcessor(conn_, [](void*, const char*) {}, nullptr);
  for (const std::string& channel : listening_) {
    PGresult* r = PQexec(conn_, ("LISTEN " + channel).c_str());
    PQclear(r);
  }
}

PgRows PgConnection::exec(const std::string& sql, const std::vector<PgParam>& params) {
  ensure_open();
  // A connection the server closed (a restart) still looks open until it is used. A statement
  // that has no effect of its own (a read, or BEGIN) outside a transaction is sent once more on
  // a new connection; anything else fails, and its caller decides (a write may have been applied
  // before the connection broke).
  const bool retry_safe = PQtransactionStatus(conn_) == PQTRANS_IDLE &&
                          (sql.rfind("SELECT", 0) == 0 || sql == "BEGIN");
  for (int attempt = 0;; ++attempt) {
    std::vector<const char*> values;
    values.reserve(params.size());
    for (const PgParam& p : params) values.push_back(p ? p->c_str() : nullptr);
    // Without parameters: the simple protocol, which also takes several statements (migrations).
    PGresult* r = params.empty() ? PQexec(conn_, sql.c_str())
                                 : PQexecParams(conn_, sql.c_str(), int(params.size()), nullptr,
                                                values.data(), nullptr, nullptr, 0);
    const ExecStatusType status = PQresultStatus(r);
    if (status == PGRES_COMMAND_OK || status == PGRES_TUPLES_OK) return PgRows(r);
    std::string why = r ? PQresultErrorMessage(r) : PQerrorMessage(conn_);
    const char* state = r ? PQresultErrorField(r, PG_DIAG_SQLSTATE) : nullptr;
    const std::string sqlstate = state ? state : "";
    PQclear(r);
    while (!why.empty() && (why.back() == '\n' || why.back() == ' ')) why.pop_back();
    const bool broken = PQstatus(conn_) != CONNECTION_OK;
    if (broken) {
      // Reopened by the next call; LISTENs are renewed then.
      PQfinish(conn_);
      conn_ = nullptr;
    }
    if (broken && retry_safe && attempt == 0) {
      ensure_open();
      continue;
    }
    throw StoreError("PostgreSQL" + (sqlstate.empty() ? "" : " " + sqlstate) + ": " + why);
  }
}

void PgConnection::rollback_quietly() {
  if (!ok()) return;
  PGresult* r = PQexec(conn_, "ROLLBACK");
  PQclear(r);
}

void PgConnection::listen(const std::string& channel) {
  // Channels are fixed identifiers of this program, never user input.
  exec("LISTEN " + channel);
  listening_.push_back(channel);
}

bool PgConnection::wait_notification(double seconds) {
  try {
    ensure_open();
  } catch (const StoreError&) {
    return true;
  }
  auto drain = [&] {
    bool any = false;
    while (PGnotify* n = PQnotifies(conn_)) {
      any = true;
      PQfreemem(n);
    }
    return any;
  };
  if (PQconsumeInput(conn_) == 0) {
    PQfinish(conn_);
    conn_ = nullptr;
    return true;
  }
  if (drain()) return true;
  pollfd fd{PQsocket(conn_), POLLIN, 0};
  const int n = ::poll(&fd, 1, int(seconds * 1000));
  if (n <= 0) return false;
  if (PQconsumeInput(conn_) == 0 || PQstatus(conn_) != CONNECTION_OK) {
    PQfinish(conn_);
    conn_ = nullptr;
    return true;
  }
  return drain();
}

}  // namespace penumbra::server
