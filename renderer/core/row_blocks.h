#pragma once
// Work over the rows of a large table (an environment map and its sampling table) split into
// blocks of whole rows that run on all cores (TBB), for loading work whose every row is
// computed independently: a row's results are the same to the bit whichever block or thread
// computes it, so splitting changes nothing but the time. Results that combine rows (a sum in
// floating point) are left to the caller, to combine in row order.
#include <algorithm>
#include <cstddef>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

namespace penumbra {

// About this many cells per block: an 8192-wide map's rows come 8 to a block (512 blocks), a
// task of ~1 ms, large enough that a block's setup (e.g. its first row's neighbour, computed
// again) stays small, small enough that two cores share the rows evenly.
constexpr size_t kRowBlockCells = size_t(1) << 16;

// Rows per block for rows of `row_cells` cells: at least 1.
inline size_t rows_per_block(size_t row_cells) {
  return std::max<size_t>(kRowBlockCells / std::max<size_t>(row_cells, 1), 1);
}

// Calls block(begin, end) for rows [0, rows) in blocks of `per_block` rows (the last one
// shorter), concurrently. The work runs isolated: a thread waiting for the blocks takes no
// other task meanwhile, so a caller may hold a lock or a std::call_once (an environment map's
// table is built inside one when a render samples it first) without a task that wants the same
// lock running on the waiting thread and deadlocking it.
template <class Block>
void for_row_blocks(size_t rows, size_t per_block, const Block& block) {
  if (rows == 0) return;
  per_block = std::max<size_t>(per_block, 1);
  const size_t blocks = (rows - 1) / per_block + 1;
  if (blocks == 1) {  // no tasks for one block
    block(size_t(0), rows);
    return;
  }
  tbb::this_task_arena::isolate([&] {
    tbb::parallel_for(size_t(0), blocks, [&](size_t b) {
      const size_t begin = b * per_block;
      block(begin, std::min(rows, begin + per_block));
    });
  });
}

}  // namespace penumbra
