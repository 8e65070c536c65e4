// libFuzzer target: arbitrary bytes through the OBJ reader (renderer/io/obj_reader.h): its
// statement reader and vertex merging. Malformed input must give a MeshFileError naming the
// file, never a crash, hang, leak, undefined behaviour or runaway allocation; a mesh that is read
// must satisfy check_mesh_file. The same bytes read in three parts (as a large file is, on
// threads) must give the same mesh, or an error too.
#include <cstdlib>
#include <optional>
#include <string_view>

#include "fuzz/mesh_file_invariants.h"
#include "renderer/io/obj_reader.h"

namespace {

// The mesh, or nullopt after an error (which must name the file).
std::optional<penumbra::MeshFile> read(const std::string& bytes, size_t parts) {
  const std::string name = "'fuzz.obj'";
  try {
    return penumbra::obj_reader_detail::parse_obj_in_parts(bytes, name,
                                                           penumbra::fuzz::fuzz_mesh_limits(), parts);
  } catch (const penumbra::MeshFileError& e) {
    if (std::string_view(e.what()).substr(0, name.size() + 2) != name + ": ") std::abort();
    return std::nullopt;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  const std::optional<penumbra::MeshFile> whole = read(bytes, 1), parts = read(bytes, 3);
  if (whole.has_value() != parts.has_value()) std::abort();
  if (!whole) return 0;
  penumbra::fuzz::check_mesh_file(*whole, penumbra::fuzz::fuzz_mesh_limits());
  if (whole->faces != parts->faces || whole->warnings != parts->warnings ||
      whole->mesh.positions != parts->mesh.positions || whole->mesh.normals != parts->mesh.normals ||
      whole->mesh.uvs != parts->mesh.uvs || whole->mesh.indices != parts->mesh.indices)
    std::abort();
  return 0;
}
