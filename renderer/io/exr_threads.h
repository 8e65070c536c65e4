#pragma once
// The threads OpenEXR compresses and decompresses a file's chunks on. OpenEXR hands a file's
// line buffers (16 lines each for ZIP) to its process-wide thread pool, which has no threads
// until its size is set: until then every EXR is encoded and decoded on the calling thread, as
// all of penumbra's were (a 1920 x 1080 RGB float EXR took 0.3-0.4 s of zlib on one core after
// its render; docs/performance.md, levers, session 41). The files are the same bytes on any
// number of threads: each chunk is compressed alone and the calling thread writes them in order.
namespace penumbra {

// The pool's size, made this machine's hardware threads (at most kMaxExrThreads) by the first
// call; what to pass OpenEXR's InputFile and OutputFile as numThreads.
int exr_threads();

// Sets the pool's size (0: every file on its caller's thread), for tests and callers that must
// keep to fewer threads.
void set_exr_threads(int count);

inline constexpr int kMaxExrThreads = 16;

}  // namespace penumbra
