#pragma once
// The farm's tables in PostgreSQL, as numbered migrations applied at start-up: every node runs
// migrate() before anything else; the first to take the advisory lock applies what is missing
// in one transaction, the others wait on the lock and then find nothing to do.
#include "server/farm/pg_connection.h"

namespace penumbra::server {

// The highest migration this build knows.
int farm_schema_version();
// Applies the missing migrations; returns the version the database is at. Throws StoreError,
// also when the database is at a version newer than this build knows (an older node must not
// write into a schema it does not understand).
int migrate_farm_schema(PgConnection& db);

}  // namespace penumbra::server
