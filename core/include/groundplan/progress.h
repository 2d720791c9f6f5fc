// SPDX-License-Identifier: MIT
#pragma once
// One callback that returns false to cancel (STYLE.md §8). sub() scales a stage into a range of the
// whole, like GDALCreateScaledProgress.
#include <functional>
#include <groundplan/error.h>

namespace groundplan {

class Progress {
 public:
  using Callback = std::function<bool(double fraction, const char* message)>;
  Progress() = default;
  explicit Progress(Callback cb) : cb_(std::move(cb)) {}

  /// Reports `fraction` (0..1 of this stage); throws Cancelled if the callback returns false.
  void report(double fraction, const char* message = "") const {
    if (cb_ && !cb_(lo_ + (hi_ - lo_) * fraction, message)) throw Cancelled();
  }
  /// A progress for the part [lo, hi] of this one.
  Progress sub(double lo, double hi) const {
    Progress p(cb_);
    p.lo_ = lo_ + (hi_ - lo_) * lo;
    p.hi_ = lo_ + (hi_ - lo_) * hi;
    return p;
  }
  explicit operator bool() const { return static_cast<bool>(cb_); }

 private:
  Callback cb_;
  double lo_ = 0, hi_ = 1;
};

}  // namespace groundplan
