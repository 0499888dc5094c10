// Sequence classification for loss, duplicate and reorder accounting.
#include "device/link/sequence_tracker.h"

namespace resecto {

void SequenceTracker::reset() {
  bits_.fill(0);
  newest_ = 0;
  started_ = false;
}

bool SequenceTracker::seen(std::uint64_t sequence) const {
  const std::uint64_t slot = sequence % kWindow;
  return (bits_[slot / 64] >> (slot % 64)) & 1u;
}

void SequenceTracker::mark(std::uint64_t sequence) {
  const std::uint64_t slot = sequence % kWindow;
  bits_[slot / 64] |= std::uint64_t{1} << (slot % 64);
}

void SequenceTracker::clear_range(std::uint64_t first, std::uint64_t last_inclusive) {
  if (last_inclusive - first + 1 >= kWindow) {
    bits_.fill(0);
    return;
  }
  for (std::uint64_t s = first; s <= last_inclusive; ++s) {
    const std::uint64_t slot = s % kWindow;
    bits_[slot / 64] &= ~(std::uint64_t{1} << (slot % 64));
  }
}

SequenceVerdict SequenceTracker::observe(std::uint32_t sequence32, std::uint64_t& unwrapped, std::uint64_t& gap) {
  gap = 0;
  if (!started_) {
    // Start one wrap up so that late reports just below the first one stay non-negative.
    newest_ = (std::uint64_t{1} << 32) + sequence32;
    started_ = true;
    bits_.fill(0);
    mark(newest_);
    unwrapped = newest_;
    return SequenceVerdict::kFirst;
  }
  // The signed 32-bit difference picks the nearest unwrapping (modular arithmetic, no overflow UB).
  const auto delta = static_cast<std::int32_t>(sequence32 - static_cast<std::uint32_t>(newest_));
  unwrapped = newest_ + static_cast<std::uint64_t>(static_cast<std::int64_t>(delta));
  if (delta > 0) {
    gap = static_cast<std::uint64_t>(delta) - 1;
    clear_range(newest_ + 1, unwrapped);  // slots reused from a window ago
    newest_ = unwrapped;
    mark(newest_);
    return SequenceVerdict::kNext;
  }
  const std::uint64_t behind = static_cast<std::uint64_t>(-static_cast<std::int64_t>(delta));
  if (behind < kWindow) {
    if (seen(unwrapped)) return SequenceVerdict::kDuplicate;
    mark(unwrapped);
    return SequenceVerdict::kLate;
  }
  // Far behind: a board that rebooted starts again near zero; anything else is too old to place.
  if (sequence32 < kWindow) {
    reset();
    (void)observe(sequence32, unwrapped, gap);  // seeds the window from this report
    return SequenceVerdict::kRestart;
  }
  return SequenceVerdict::kStale;
}

}  // namespace resecto
