#include "server/storage/disk_space.h"

#include <sys/statvfs.h>

namespace penumbra::server {

std::optional<std::uint64_t> available_bytes(const std::string& dir) {
  struct statvfs s {};
  if (::statvfs(dir.c_str(), &s) != 0) return std::nullopt;
  return std::uint64_t(s.f_bavail) * std::uint64_t(s.f_frsize);
}

std::uint64_t worst_case_result_bytes(int width, int height, std::uint32_t outputs) {
  const std::uint64_t pixels = std::uint64_t(width) * std::uint64_t(height);
  const std::uint64_t exr = pixels * 16;
  const std::uint64_t png_raw = pixels * 4 + std::uint64_t(height);
  // Deflate never grows data by more than 5 bytes per 64 KiB stored block (RFC 1951 3.2.4).
  const std::uint64_t png = png_raw + (png_raw / 65535 + 1) * 5;
  // A layer: at most 3 float channels in each multi-layer EXR and in its own, and a PNG.
  const std::uint64_t layer = 3 * pixels * 12 + png + (16u << 10);
  const std::uint64_t layers = std::uint64_t(__builtin_popcount(outputs)) * layer;
  const std::uint64_t blender = outputs ? exr : 0;  // the Blender-layout copy (with layers only)
  return exr + png + blender + layers + (64u << 10);
}

}  // namespace penumbra::server
