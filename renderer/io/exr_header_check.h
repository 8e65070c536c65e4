#pragma once
// What every EXR read from untrusted bytes goes through first: a walk of the header that refuses
// attribute sizes OpenEXR 3.1 would allocate before reading (exr_header_check.cpp says why), and
// an OpenEXR input stream over bytes in memory. Used by the window reader (exr_window_file.h) and
// the image asset reader (exr_reader.h).
#include <OpenEXR/ImfIO.h>

#include <cstdint>
#include <string>
#include <vector>

namespace penumbra {

// The file's first bytes the walk reads at most; a header beyond them is refused.
constexpr size_t kMaxExrHeaderBytes = size_t(1) << 20;
// Flags of the version field (OpenEXR file layout).
constexpr uint32_t kExrTiled = 0x200, kExrDeep = 0x800, kExrMultiPart = 0x1000;

// Walks the single-part header in `head` (the file's first min(size, kMaxExrHeaderBytes) bytes;
// `file_size` the whole file's) and throws ImageIoError("<path>: ...") for a file that is not an
// EXR or whose attributes claim sizes beyond the file or unlike their types' layouts. Returns the
// version field's flags; a multi-part or deep file's header is not walked (its layout differs):
// the caller refuses it or hands it to a reader that walks it.
uint32_t check_exr_header(const uint8_t* head, size_t head_size, uint64_t file_size, const std::string& path);
// The same for a file, whose first bytes are read here; also throws when it cannot be read.
uint32_t check_exr_file_header(const std::string& path);

// Encoded bytes held in memory as an OpenEXR input stream (`bytes` must outlive it).
class ExrMemoryStream : public Imf::IStream {
 public:
  ExrMemoryStream(const std::string& name, const std::vector<uint8_t>& bytes);
  bool read(char c[], int n) override;
  uint64_t tellg() override { return pos_; }
  void seekg(uint64_t pos) override { pos_ = pos; }

 private:
  const std::vector<uint8_t>& bytes_;
  uint64_t pos_ = 0;
};

}  // namespace penumbra
