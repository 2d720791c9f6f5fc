// SPDX-License-Identifier: MIT
// libgroundplan.so is groundplan_core + groundplan_gis linked whole (cmake/packaging.cmake); this
// file only gives the target a source of its own.
namespace groundplan {
extern const char* const kLibraryName;
const char* const kLibraryName = "libgroundplan";
}  // namespace groundplan
