#pragma once
// The progressive passes of a render: how many samples per pixel each pass takes. Passes exist
// for three things -- a preview after each (RenderControl::on_pass), a time budget that ends the
// render with every pixel about equally sampled, and adaptive sampling, whose limits are decided
// between passes from its min_samples on -- and each boundary costs: a pass visits every pixel
// again (its sampler's dimension seeds derived again), its batches hold a few samples of many
// pixels instead of a run of one pixel's, and the threads wait for its last tile
// (docs/performance.md, levers, sessions 21-22).
#include <climits>

namespace penumbra {

struct PassPlan {
  int spp = 1;    // samples per pixel in all
  int first = 1;  // the first pass's samples
  // From this many samples on the boundaries double exactly (adaptive sampling's min_samples:
  // its limits are decided after 16, 32, 64, ... samples whatever else asks for passes, so the
  // image does not depend on previews). INT_MAX: uniform sampling, any boundaries.
  int fixed_from = INT_MAX;
  // A pass after the first lasts at least about this long at the rate the previous pass
  // measured (where boundaries are free): previews then come about this often or less, not
  // after 1, 1, 2, 4, ... samples however fast those are. 0: plain doubling.
  double min_seconds = 0.0;

  // The samples of the pass after `done` samples per pixel, given the previous pass's seconds
  // per sample per pixel (0 if unknown); 0 once done reaches spp. After the first pass the
  // sizes double (first, first, 2 first, ...), raised by min_seconds where boundaries are free.
  int next(int done, double seconds_per_sample) const;
};

}  // namespace penumbra
