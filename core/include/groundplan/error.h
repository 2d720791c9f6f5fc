// SPDX-License-Identifier: MIT
#pragma once
// Exceptions thrown inside groundplan; converted once at each boundary (CLI main, driver entry points).
#include <stdexcept>
#include <string>

namespace groundplan {

struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};
/// Input that cannot be read at all (the file, not one building): message names the file.
struct InputError : Error {
  using Error::Error;
};
/// A geometric decision failed even at the highest precision; carries where.
struct TopologyError : Error {
  TopologyError(const std::string& what, double x, double y) : Error(what), x(x), y(y) {}
  double x, y;
};
struct InvalidArgument : Error {
  using Error::Error;
};
struct GpuError : Error {
  using Error::Error;
};
/// The progress callback asked to stop.
struct Cancelled : Error {
  Cancelled() : Error("cancelled by the caller") {}
};

}  // namespace groundplan
