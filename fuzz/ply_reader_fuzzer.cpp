// libFuzzer target: arbitrary bytes through the PLY reader (renderer/io/ply_reader.h). Malformed
// input must give a MeshFileError naming the file, never a crash, hang, leak, undefined
// behaviour or an allocation beyond the limits (the build adds ASan and UBSan; scripts/fuzz.sh
// caps memory); a mesh that is read must satisfy check_mesh_file.
#include "fuzz/mesh_file_invariants.h"
#include "renderer/io/ply_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  penumbra::fuzz::fuzz_mesh_reader<penumbra::parse_ply>(data, size, "'fuzz.ply'");
  return 0;
}
