// libFuzzer target: arbitrary bytes through the OBJ reader (renderer/io/obj_reader.h): its
// screening and tinyobjloader behind it, compiled with the same sanitizers and coverage
// (renderer/io/tiny_obj_loader_impl.cpp). Malformed input must give a MeshFileError naming the
// file, never a crash, hang, leak, undefined behaviour or runaway allocation; a mesh that is read
// must satisfy check_mesh_file.
#include "fuzz/mesh_file_invariants.h"
#include "renderer/io/obj_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  penumbra::fuzz::fuzz_mesh_reader<penumbra::parse_obj>(data, size, "'fuzz.obj'");
  return 0;
}
