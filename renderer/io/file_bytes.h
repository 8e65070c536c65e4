#pragma once
// A file's bytes for a parser: mapped into memory, not copied. Reading a 109 MB OBJ file into a
// string took 70-110 ms on the bench machine (the copy out of the page cache and a page fault
// per 4 KB of the new string); mapping it with its pages populated takes 11-15 ms
// (docs/mesh-files.md). A mapped file that shrinks while it is mapped would raise SIGBUS where
// the lost pages are read; a process-wide SIGBUS handler (installed with the first mapping, other
// signals passed to the handler before it) maps zero pages there instead and marks the mapping,
// so the reader sees zeros and the caller reports the file as changed (`intact()`): never a
// crash.
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

namespace penumbra {

// A file that cannot be opened, is not a regular file or is over the size limit: `what()` is
// the reason without the file's name (callers add it).
struct FileBytesError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class FileBytes {
 public:
  FileBytes() = default;
  // Bytes already in memory (tests, fuzzers, bytes from elsewhere): owned, never mapped.
  FileBytes(std::string bytes) : owned_(std::move(bytes)), view_(owned_) {}  // NOLINT implicit
  FileBytes(const char* bytes) : FileBytes(std::string(bytes)) {}            // NOLINT implicit
  FileBytes(FileBytes&& other) noexcept { *this = std::move(other); }
  FileBytes& operator=(FileBytes&& other) noexcept;
  FileBytes(const FileBytes&) = delete;
  FileBytes& operator=(const FileBytes&) = delete;
  ~FileBytes() { release(); }

  // The regular file at `path`, mapped read-only with its pages populated; its size is checked
  // against max_bytes before anything is mapped. Throws FileBytesError ("cannot open the file",
  // "cannot read the file", "the file has N bytes; at most M are allowed"). An empty file, or one
  // mapped while every guard slot is in use (64 files mapped at once), is read into memory.
  static FileBytes map(const std::filesystem::path& path, int64_t max_bytes);

  std::string_view view() const { return view_; }
  // False once a page of the mapping was found gone (the file shrank while mapped, or the page
  // could not be read from the disk; those bytes read as zeros). Kept after release().
  bool intact() const;
  // Unmaps or frees the bytes (view() is empty afterwards), e.g. to lower the peak memory once
  // a parser has what it needs.
  void release();

 private:
  std::string owned_;
  std::string_view view_;
  void* mapping_ = nullptr;  // of mapped_bytes_ (a whole number of pages)
  size_t mapped_bytes_ = 0;
  int slot_ = -1;  // the SIGBUS guard's slot while mapped
  bool lost_ = false;  // intact() after release()
};

}  // namespace penumbra
