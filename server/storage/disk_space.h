#pragma once
// Free space of the data directory's file system, and what one job may need of it. Checked before
// a job is accepted (507 when it would not fit) and by /readyz (not ready below the margin), so a
// full disk is reported when work is offered, not found out when a render's images fail to write
// (issue 15 item 5).
#include <cstdint>
#include <optional>
#include <string>

namespace penumbra::server {

// Bytes an unprivileged writer may still use there (statvfs f_bavail * f_frsize); nullopt when
// the file system cannot be asked.
std::optional<std::uint64_t> available_bytes(const std::string& dir);

// An upper bound on the stored images of a width x height job: the EXR at 32-bit float RGBA
// uncompressed (16 bytes a pixel) plus the PNG at 8-bit RGBA with deflate's stored-block worst case
// and a filter byte a row, plus 64 KiB of headers and metadata; with output layers (`outputs`, a
// RenderSettings::outputs bit set) the EXR again in Blender's layout and, per layer, its
// channels in both multi-layer EXRs and its own EXR and PNG (docs/output-layers.md).
std::uint64_t worst_case_result_bytes(int width, int height, std::uint32_t outputs = 0);

}  // namespace penumbra::server
