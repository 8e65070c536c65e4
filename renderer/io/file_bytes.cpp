#include "renderer/io/file_bytes.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <mutex>

namespace penumbra {
namespace {

// ---- The SIGBUS guard ------------------------------------------------------------------------
//
// Each live mapping holds a slot with its address range. A SIGBUS whose address lies in a slot's
// range is a page the file no longer has (it was truncated after it was mapped; Linux sends
// SIGBUS for the pages of a file mapping past the file's end) or one the kernel could not read
// from the disk: the handler maps anonymous zero
// pages over the rest of the range, marks the slot and returns, so the faulting read is repeated
// and reads zeros. Any other SIGBUS goes to the handler installed before ours, or ends the
// process as the default action does. The handler reads only atomics and calls mmap, signal and
// raise (plain system calls on Linux).

constexpr int kSlots = 64;
struct Slot {
  std::atomic<bool> used{false};
  std::atomic<uintptr_t> begin{0}, end{0};
  std::atomic<bool> lost{false};
};
Slot g_slots[kSlots];
struct sigaction g_previous;
std::once_flag g_install;
uintptr_t g_page_size = 4096;

void on_sigbus(int signal_number, siginfo_t* info, void* context) {
  const uintptr_t address = reinterpret_cast<uintptr_t>(info->si_addr);
  for (Slot& slot : g_slots) {
    const uintptr_t begin = slot.begin.load(std::memory_order_acquire);
    const uintptr_t end = slot.end.load(std::memory_order_acquire);
    if (begin == 0 || address < begin || address >= end) continue;
    const uintptr_t page = address & ~(g_page_size - 1);
    if (mmap(reinterpret_cast<void*>(page), end - page, PROT_READ,
             MAP_PRIVATE | MAP_ANONYMOUS | MAP_FIXED, -1, 0) != MAP_FAILED) {
      slot.lost.store(true, std::memory_order_release);
      return;
    }
  }
  if ((g_previous.sa_flags & SA_SIGINFO) && g_previous.sa_sigaction) {
    g_previous.sa_sigaction(signal_number, info, context);
    return;
  }
  if (!(g_previous.sa_flags & SA_SIGINFO) && g_previous.sa_handler != SIG_DFL &&
      g_previous.sa_handler != SIG_IGN) {
    g_previous.sa_handler(signal_number);
    return;
  }
  signal(SIGBUS, SIG_DFL);
  raise(SIGBUS);
}

void install_guard() {
  g_page_size = uintptr_t(sysconf(_SC_PAGESIZE));
  struct sigaction action = {};
  action.sa_sigaction = on_sigbus;
  action.sa_flags = SA_SIGINFO | SA_ONSTACK;
  sigemptyset(&action.sa_mask);
  // The handler before ours recorded first, so a SIGBUS arriving as ours is installed finds it.
  sigaction(SIGBUS, nullptr, &g_previous);
  sigaction(SIGBUS, &action, nullptr);
}

int claim_slot(uintptr_t begin, uintptr_t end) {
  for (int i = 0; i < kSlots; ++i) {
    bool expected = false;
    if (!g_slots[i].used.compare_exchange_strong(expected, true)) continue;
    g_slots[i].lost.store(false);
    g_slots[i].end.store(end, std::memory_order_release);
    g_slots[i].begin.store(begin, std::memory_order_release);
    return i;
  }
  return -1;
}

bool free_slot(int i) {
  g_slots[i].begin.store(0, std::memory_order_release);
  g_slots[i].end.store(0, std::memory_order_release);
  const bool lost = g_slots[i].lost.load(std::memory_order_acquire);
  g_slots[i].used.store(false, std::memory_order_release);
  return lost;
}

struct Descriptor {
  int fd;
  ~Descriptor() {
    if (fd >= 0) ::close(fd);
  }
};

}  // namespace

FileBytes& FileBytes::operator=(FileBytes&& other) noexcept {
  if (this == &other) return *this;
  release();
  lost_ = other.lost_;
  mapping_ = other.mapping_;
  mapped_bytes_ = other.mapped_bytes_;
  slot_ = other.slot_;
  if (mapping_) {
    view_ = other.view_;
  } else {
    owned_ = std::move(other.owned_);
    view_ = owned_;
  }
  other.mapping_ = nullptr;
  other.mapped_bytes_ = 0;
  other.slot_ = -1;
  other.view_ = {};
  other.owned_.clear();
  return *this;
}

FileBytes FileBytes::map(const std::filesystem::path& path, int64_t max_bytes) {
  const Descriptor file{::open(path.c_str(), O_RDONLY | O_CLOEXEC)};
  if (file.fd < 0) throw FileBytesError("cannot open the file");
  struct stat info = {};
  if (::fstat(file.fd, &info) != 0 || !S_ISREG(info.st_mode))
    throw FileBytesError("cannot read the file");
  const int64_t size = int64_t(info.st_size);
  if (size > max_bytes)
    throw FileBytesError("the file has " + std::to_string(size) + " bytes; at most " +
                         std::to_string(max_bytes) + " are allowed");
  FileBytes out;
  if (size == 0) return out;
  std::call_once(g_install, install_guard);
  const size_t mapped = (size_t(size) + g_page_size - 1) & ~(g_page_size - 1);
  void* const p = ::mmap(nullptr, mapped, PROT_READ, MAP_PRIVATE | MAP_POPULATE, file.fd, 0);
  if (p != MAP_FAILED) {
    const uintptr_t begin = reinterpret_cast<uintptr_t>(p);
    const int slot = claim_slot(begin, begin + mapped);
    if (slot >= 0) {
      out.mapping_ = p;
      out.mapped_bytes_ = mapped;
      out.slot_ = slot;
      out.view_ = std::string_view(static_cast<const char*>(p), size_t(size));
      return out;
    }
    ::munmap(p, mapped);
  }
  // No slot (or no mapping): the bytes read into memory, at most `size` of them.
  std::string bytes(size_t(size), '\0');
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::pread(file.fd, bytes.data() + done, bytes.size() - done, off_t(done));
    if (n <= 0) throw FileBytesError("cannot read the file");
    done += size_t(n);
  }
  return FileBytes(std::move(bytes));
}

bool FileBytes::intact() const {
  if (slot_ >= 0 && g_slots[slot_].lost.load(std::memory_order_acquire)) return false;
  return !lost_;
}

void FileBytes::release() {
  if (mapping_) {
    lost_ |= free_slot(slot_);
    ::munmap(mapping_, mapped_bytes_);
    mapping_ = nullptr;
    mapped_bytes_ = 0;
    slot_ = -1;
  }
  std::string().swap(owned_);
  view_ = {};
}

}  // namespace penumbra
