// SPDX-License-Identifier: MIT
#include "csv_slices.h"

#include <cpl_string.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <vector>

namespace groundplan::output {
namespace {

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

/// Appends `part` past its first line (the header) to `out`; false when it cannot be read or has no header line.
bool append_rows(const std::string& part, std::FILE* out, std::string& why) {
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> in(std::fopen(part.c_str(), "rb"), std::fclose);
  if (!in) {
    why = "cannot read " + part;
    return false;
  }
  std::vector<char> buf(std::size_t(1) << 20);
  bool past_header = false;
  for (;;) {
    const std::size_t n = std::fread(buf.data(), 1, buf.size(), in.get());
    if (n == 0) break;
    std::size_t from = 0;
    if (!past_header) {
      while (from < n && buf[from] != '\n') ++from;
      if (from == n) continue;  // the header goes on
      past_header = true;
      ++from;
    }
    if (std::fwrite(buf.data() + from, 1, n - from, out) != n - from) {
      why = "cannot write the destination (disk full?)";
      return false;
    }
  }
  if (std::ferror(in.get()) || !past_header) {
    why = "cannot read " + part + (past_header ? "" : " (no header line)");
    return false;
  }
  return true;
}

}  // namespace

bool is_csv_file(const std::string& format, const std::string& dst) {
  if (dst.rfind("/vsi", 0) == 0) return false;
  const std::string ext = lower(std::filesystem::path(dst).extension().string());
  return ext == ".csv" && (format.empty() || lower(format) == "csv");
}

int csv_writers(const std::vector<std::string>& flags, const std::vector<std::string>& layers,
                const std::string& plans_layer, std::size_t plans, int threads, std::string* why_one) {
  auto one = [&](std::string why) {
    if (why_one) *why_one = std::move(why);
    return 1;
  };
  const int writers = writers_for(plans, threads, why_one);
  if (writers < 2) return 1;
  if (layers.size() != 1) return one("a CSV file of several layers");
  std::string why = slices_ruled_out(flags, layers, plans_layer);
  if (!why.empty()) return one(std::move(why));
  for (std::size_t i = 0; i + 1 < flags.size(); ++i) {
    if (flags[i] == "-dsco") return one("-dsco " + flags[i + 1]);
    if (flags[i] != "-lco") continue;
    const std::string key = lower(flags[i + 1].substr(0, flags[i + 1].find('=')));
    if (key != "geometry" && key != "separator" && key != "lineformat" && key != "string_quoting")
      return one("-lco " + flags[i + 1]);
  }
  return writers;
}

SliceOutcome write_csv_slices(const SliceWrite& w, const SliceSource& source, const Translate& translate) {
  using clock = std::chrono::steady_clock;
  SliceOutcome out;
  const std::vector<std::string> paths = slice_paths(w.dst, std::max(1, w.writers), ".csv");
  const std::vector<std::string> parts(paths.begin() + 1, paths.end());
  auto remove_parts = [&] {
    for (const auto& p : parts) remove_with_sidecars(p);
  };
  remove_parts();
  auto fail = [&](std::string why) {
    out.error = std::move(why);
    remove_parts();
    remove_with_sidecars(w.dst);
    return out;
  };
  if (!write_slices_side_by_side(w, source, translate, paths, {}, out)) return fail(out.error);

  const auto t1 = clock::now();
  {
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(w.dst.c_str(), "ab"), std::fclose);
    if (!f) return fail("cannot open " + w.dst + " to append the slices");
    std::string why;
    for (const std::string& p : parts)
      if (!append_rows(p, f.get(), why)) return fail("appending the slices failed: " + why);
    if (std::fflush(f.get()) != 0) return fail("appending the slices failed: cannot write " + w.dst);
  }
  out.merge_s = std::chrono::duration<double>(clock::now() - t1).count();
  remove_parts();
  out.ok = true;
  return out;
}

}  // namespace groundplan::output
