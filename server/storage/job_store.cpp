#include "server/storage/job_store.h"

namespace penumbra::server {

std::string describe(const JobChange& change) {
  if (const auto* i = std::get_if<InsertJob>(&change)) return "insert " + i->record.id;
  if (const auto* u = std::get_if<UpdateJob>(&change))
    return "update " + u->record.id + " " + to_string(u->record.state);
  return "erase " + std::get<EraseJob>(change).id;
}

}  // namespace penumbra::server
