#pragma once
// Test helpers for the asset store (issue 12): what a well-behaved client does to submit a job
// with files: ask which hashes the server lacks, upload only those, then submit the manifest.
#include <map>
#include <string>

#include "server/storage/sha256.h"
#include "server_process.h"

namespace penumbra::test {

inline std::string sha(const std::string& bytes) { return server::sha256_hex(bytes); }

inline httplib::Result put_asset(httplib::Client& c, const std::string& bytes,
                                 const std::string& hash = "") {
  return c.Put(("/v1/assets/" + (hash.empty() ? sha(bytes) : hash)).c_str(), bytes,
               "application/octet-stream");
}

struct AssetSubmission {
  int status = -1;  // of POST /v1/jobs
  std::string body;
  std::size_t bytes_uploaded = 0;  // asset bodies sent with PUT
  int uploads = 0;
};

// files: manifest name -> contents.
inline AssetSubmission submit_with_assets(httplib::Client& c, const Json& scene,
                                          const std::map<std::string, std::string>& files) {
  AssetSubmission out;
  Json manifest = Json::object();
  Json hashes = Json::array();
  std::map<std::string, const std::string*> by_hash;
  for (const auto& [name, bytes] : files) {
    const std::string h = sha(bytes);
    manifest[name] = "sha256:" + h;
    hashes.push_back("sha256:" + h);
    by_hash["sha256:" + h] = &bytes;
  }
  auto missing = post_json(c, "/v1/assets/missing", Json{{"hashes", hashes}}.dump());
  if (!missing || missing->status != 200)
    throw std::runtime_error("POST /v1/assets/missing failed");
  const Json missing_list = Json::parse(missing->body).at("missing");
  for (const auto& h : missing_list) {
    const std::string& bytes = *by_hash.at(h.get<std::string>());
    auto put = put_asset(c, bytes);
    if (!put || (put->status != 201 && put->status != 200))
      throw std::runtime_error("PUT asset failed: " + (put ? put->body : std::string("no answer")));
    out.bytes_uploaded += bytes.size();
    ++out.uploads;
  }
  auto res = post_json(c, "/v1/jobs", Json{{"scene", scene}, {"assets", manifest}}.dump());
  if (!res) throw std::runtime_error("POST /v1/jobs: no answer");
  out.status = res->status;
  out.body = res->body;
  return out;
}

// The scenes/mesh_file.json scene (a PLY trefoil) at a tiny size, and its mesh's bytes.
inline Json mesh_file_scene(int size = 16, int spp = 1) {
  Json scene = Json::parse(read_file(std::string(PENUMBRA_SOURCE_DIR) + "/scenes/mesh_file.json"));
  scene["render"]["width"] = size;
  scene["render"]["height"] = size;
  scene["render"]["spp"] = spp;
  return scene;
}
inline std::string trefoil_ply() {
  return read_file(std::string(PENUMBRA_SOURCE_DIR) + "/scenes/meshes/trefoil.ply");
}

}  // namespace penumbra::test
