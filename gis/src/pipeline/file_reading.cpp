// SPDX-License-Identifier: MIT
// One file through read -> working frame -> footprints (issue 14). A CityGML file of two chunks or
// more is read in chunks side by side (citygml_chunks.h) and the result checked against what the
// whole-file reading would give; otherwise, and when that check fails, the file is read whole, its
// footprints made on the other cores while the reader reads on.
#include "pipeline/file_reading.h"
#include "citygml/in_memory.h"
#include "citygml/srs_scan.h"
#include "files_read.h"

#include <groundplan/error.h>
#include <groundplan/gis/citygml_chunks.h>
#include <groundplan/gis/ogr_ranges.h>
#include <groundplan/gis/reader.h>

#include <cpl_vsi.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <unordered_set>

namespace groundplan::gis::detail {
namespace {

FootprintSource to_core(FootprintMode m) {
  switch (m) {
    case FootprintMode::Auto: return FootprintSource::Auto;
    case FootprintMode::GroundSurface: return FootprintSource::GroundSurface;
    case FootprintMode::Decompose: return FootprintSource::Decompose;
  }
  return FootprintSource::Auto;
}

/// The meshes of one reading (a whole file, or one chunk of it) and their footprints, in reading order.
struct Part {
  struct Slot {
    Mesh mesh;                    // until its footprint is made
    std::size_t problem_pos = 0;  // where its problem goes among the others (problems.size() then)
    FootprintResult fp;           // fp.footprint.source_id names the building, made or not
    std::string collapsed;        // set when georeferencing shrank it to nothing: why its footprint failed
  };
  std::string collapsed_next;  // Placer -> FootprintMaker::add: the next slot's `collapsed`
  std::vector<Problem> problems;
  std::deque<Slot> slots;  // stable addresses: a footprint task holds a pointer to its slot
  std::size_t buildings_read = 0, buildings_dropped = 0;
  std::unordered_set<std::string> delivered;  // ids of the meshes read
};

/// Georeferences the meshes of one reading as the whole-file reading does: CityGML meshes through one
/// WorkingFrame, made at the first mesh from the srsName known then (KML and glTF meshes arrive placed).
class Placer {
 public:
  /// A frame kept by a thread between the chunks of one file it reads: made once, not once a chunk
  /// (making one costs tens of ms when PROJ must find the operation, e.g. geographic to UTM).
  struct Kept {
    std::string srs;
    std::unique_ptr<WorkingFrame> frame;
  };

  /// `decision`: where the file's first mesh fixed the working CRS (for a chunk after that mesh).
  /// `kept`: a frame to take when its srsName is the one this reading needs, and to give back at the end.
  Placer(const std::string& file, const PipelineOptions& options, const ReadContext& context,
         const bool& in_working_crs, const SourceInfo& citygml, std::optional<std::array<double, 2>> decision = {},
         Kept* kept = nullptr, const ReadInfo* read_info = nullptr)
      : file_(file), options_(options), context_(context), in_working_crs_(in_working_crs), citygml_(citygml),
        decision_(decision), kept_(kept), read_info_(read_info) {}
  ~Placer() {
    if (kept_ && frame) {
      kept_->srs = frame_srs;
      kept_->frame = std::move(frame);
    }
  }
  Placer(const Placer&) = delete;
  Placer& operator=(const Placer&) = delete;

  /// False when the mesh cannot be placed (a Problem says why); throws when the file's CRS cannot
  /// hold it (the building is named by a Problem, and the file stops there).
  bool place(Mesh& mesh, Part& part) {
    ++part.buildings_read;
    part.delivered.insert(mesh.source_id);
    std::string reason;
    bool placed = true;
    try {
      if (!in_working_crs_ && !frame) {
        CrsOptions crs;
        crs.target_srs = context_.working_definition;
        // --axis-order wins; else the order the format fixes (OGR: GDAL's data axis order), else the CRS's rule.
        const AxisOrder format_axis = read_info_ ? read_info_->source_axis : AxisOrder::Auto;
        crs.source_axis = options_.source_axis != AxisOrder::Auto ? options_.source_axis : format_axis;
        // A CityGML srsName (not -s_srs) in the short form "EPSG:n": GDAL's GML convention, longitude first.
        crs.gml_short_epsg_east_first =
            options_.s_srs.empty() && (!read_info_ || read_info_->format == InputFormat::CityGml);
        // -s_srs / -a_srs win; else the CRS the format gives (OGR: the layer's), else the srsName read so far.
        frame_srs = !options_.s_srs.empty()                             ? options_.s_srs
                    : read_info_ && !read_info_->source_srs.empty() ? read_info_->source_srs
                                                                    : citygml_.srs_name;
        // A CityGML file (a chunk's format is not set: only CityGML is read in chunks) that names its CRS only
        // after its first building, on another object's envelope: that srsName holds for the whole file.
        const InputFormat format = read_info_ ? read_info_->format : InputFormat::CityGml;
        if (frame_srs.empty() && options_.s_srs.empty() &&
            (format == InputFormat::CityGml || format == InputFormat::Unknown)) {
          frame_srs = citygml::first_srs_name_in(file_);
          srs_found_later = !frame_srs.empty();
        }
        if (kept_ && kept_->frame && kept_->srs == frame_srs)
          frame = std::move(kept_->frame);  // same srsName, options and decision: the same frame
        else
          frame = make_frame(crs);
        if (decision_ && !frame->decided()) frame->decide((*decision_)[0], (*decision_)[1]);
        // The file's first building (not a later chunk's: those come with decision_) against the
        // area of use of the CRS it is read in: a wrong label says so once, naming that building.
        check_area = !decision_ && !mesh.vertices.empty();
      }
      if (without_crs) {
        // No CRS among georeferenced inputs: the building cannot be placed; the file's NO_CRS problem says why.
        part.problems.push_back({mesh.source_id, file_, "georeference", "NO_CRS",
                                 "its file has no CRS, unlike the other inputs (" + context_.working_definition +
                                     "): left out (the file's NO_CRS problem says more)"});
        ++part.buildings_dropped;
        return false;
      }
      const bool georeferenced = in_working_crs_ || (frame && frame->source_known());
      if (georeferenced && !context_.unknown_frame_file.empty() && !context_.georeferenced_wins)
        throw InvalidArgument(file_ + ": has a CRS, but " + context_.unknown_frame_file +
                              " (read before it) has none, so their coordinates cannot be combined; give every "
                              "input a CRS, or process them separately");
      if (frame && !frame->decided() && !mesh.vertices.empty()) {
        // What WorkingFrame::transform would decide from; kept for the chunks after this one.
        double lo_x = mesh.vertices[0].x, hi_x = lo_x, lo_y = mesh.vertices[0].y, hi_y = lo_y;
        for (const Point3& p : mesh.vertices) {
          lo_x = std::min(lo_x, p.x), hi_x = std::max(hi_x, p.x);
          lo_y = std::min(lo_y, p.y), hi_y = std::max(hi_y, p.y);
        }
        decided_at = std::array<double, 2>{(lo_x + hi_x) / 2, (lo_y + hi_y) / 2};
        frame->decide((*decided_at)[0], (*decided_at)[1]);
      }
      if (check_area) {
        check_area = false;
        const std::array<double, 4> box = extent_of(mesh);
        const std::string warning = frame->area_of_use_mismatch((box[0] + box[2]) / 2, (box[1] + box[3]) / 2);
        if (!warning.empty()) {
          // Stage "read", not "georeference": a georeference- or footprint-stage problem naming a building
          // means that building was dropped (the accounting in the problems layer); this one drops nothing.
          part.problems.push_back({mesh.source_id, file_, "read", "CRS_OUTSIDE_AREA_OF_USE", warning});
          area_warning = true;
        }
      }
      const std::array<double, 4> before = extent_of(mesh);
      placed = !frame || frame->transform(mesh, &reason);
      if (placed && frame && !mesh.vertices.empty()) note_collapse(mesh, before, part);
    } catch (const Error& e) {
      // The file's CRS cannot hold this building (EPSG:4326 on metres ...): the file's fault, so the
      // file stops here (the caller's catch); this building is named too, so that it is not lost.
      part.problems.push_back({mesh.source_id, file_, "georeference", "CRS_MISMATCH", e.what()});
      ++part.buildings_dropped;
      throw;
    }
    if (!placed) {
      part.problems.push_back({mesh.source_id, file_, "georeference", "TRANSFORM_FAILED", reason});
      ++part.buildings_dropped;
    }
    return placed;
  }

  /// min x, min y, max x, max y of the mesh's vertices (all zero for none).
  static std::array<double, 4> extent_of(const Mesh& mesh) {
    if (mesh.vertices.empty()) return {0, 0, 0, 0};
    std::array<double, 4> b{mesh.vertices[0].x, mesh.vertices[0].y, mesh.vertices[0].x, mesh.vertices[0].y};
    for (const Point3& p : mesh.vertices) {
      b[0] = std::min(b[0], p.x), b[1] = std::min(b[1], p.y);
      b[2] = std::max(b[2], p.x), b[3] = std::max(b[3], p.y);
    }
    return b;
  }

  /// A building that had extent as read but is less than kCollapsed metres across once placed, where the
  /// frame warned about the file's CRS or the transform shrank it a thousandfold (degrees read as metres,
  /// a wrong label): its footprint's failure is then told as DEGENERATE_AFTER_GEOREFERENCING.
  void note_collapse(const Mesh& mesh, const std::array<double, 4>& before, Part& part) const {
    constexpr double kCollapsed = 0.05;  // metres: no building is 5 cm across
    const std::array<double, 4> after = extent_of(mesh);
    const double was = std::max(before[2] - before[0], before[3] - before[1]);
    const double is = std::max(after[2] - after[0], after[3] - after[1]);
    if (!(was > 0) || !(is < kCollapsed) || !(area_warning || is < was * 1e-3)) return;
    char buf[160];
    std::snprintf(buf, sizeof buf, "%.3g units across as read, %.3g m across in the working CRS", was, is);
    part.collapsed_next = "degenerate after georeferencing: the building is " + std::string(buf) + " (" +
                          frame->source().text.substr(0, 120) + " read as " + frame->working_crs().name +
                          "): its coordinates are not in the CRS the file names (degrees read as metres?); name "
                          "their CRS with -s_srs";
  }

  /// The frame for frame_srs. Where the working CRS comes from another file (not -t_srs) and this file has no CRS,
  /// a frame without target, and without_crs set: a file without CRS cannot join georeferenced ones.
  std::unique_ptr<WorkingFrame> make_frame(const CrsOptions& crs) {
    try {
      return std::make_unique<WorkingFrame>(frame_srs, crs, file_);
    } catch (const InvalidArgument&) {
      if (!options_.t_srs.empty() || crs.target_srs.empty()) throw;  // -t_srs asked for: its own message
      CrsOptions own = crs;
      own.target_srs.clear();
      auto f = std::make_unique<WorkingFrame>(frame_srs, own, file_);
      if (f->source_known()) throw;
      without_crs = true;
      return f;
    }
  }

  std::unique_ptr<WorkingFrame> frame;
  bool without_crs = false;   // the file has no CRS, the other inputs have one: its buildings are left out
  bool srs_found_later = false;  // the srsName was found after the first building (citygml/srs_scan.h)
  bool check_area = false;    // the next mesh is the file's first: check it against the CRS's area of use
  bool area_warning = false;  // that check warned
  std::string frame_srs;                             // the srsName the frame was made from
  std::optional<std::array<double, 2>> decided_at;   // set when this reading's first mesh fixed the working CRS

 private:
  const std::string& file_;
  const PipelineOptions& options_;
  const ReadContext& context_;
  const bool& in_working_crs_;
  const SourceInfo& citygml_;
  std::optional<std::array<double, 2>> decision_;
  Kept* kept_ = nullptr;
  const ReadInfo* read_info_ = nullptr;  // whole-file reading: the CRS any format gives (ReadInfo::source_srs)
};

/// Footprints on the other cores while the reader reads on, each into its slot in reading order, so
/// that the output and the problems come out exactly as if made one by one. When too many wait, the
/// reader makes the next one itself: memory stays bounded (a slot holds its mesh until then).
class FootprintMaker {
 public:
  FootprintMaker(const PipelineOptions& options, bool spawn) : spawn_(spawn) {
    params_.source = to_core(options.footprints);
    max_pending_ = 16 * static_cast<std::size_t>(std::max(1, tbb::this_task_arena::max_concurrency()));
  }
  ~FootprintMaker() {  // the tasks use the slots: never leave with one still running
    tasks_.cancel();
    try {
      tasks_.wait();
    } catch (...) {
    }
  }
  void add(Mesh&& mesh, Part& part) {
    Part::Slot& slot = part.slots.emplace_back();
    slot.mesh = std::move(mesh);
    slot.collapsed = std::move(part.collapsed_next);
    part.collapsed_next.clear();
    slot.problem_pos = part.problems.size();
    if (!spawn_ || pending_.load(std::memory_order_relaxed) >= max_pending_) {
      make(slot);
      return;
    }
    pending_.fetch_add(1, std::memory_order_relaxed);
    tasks_.run([this, s = &slot] {
      make(*s);
      pending_.fetch_sub(1, std::memory_order_relaxed);
    });
  }
  void wait() { tasks_.wait(); }

 private:
  void make(Part::Slot& s) const {
    s.fp = make_footprint(s.mesh, params_);
    s.mesh = Mesh{};
  }
  FootprintParams params_;
  bool spawn_;
  std::size_t max_pending_;
  std::atomic<std::size_t> pending_{0};
  tbb::task_group tasks_;
};

/// Frees the elements of `v` on every core (each holds many small blocks: ids, hash nodes), then `v`.
template <class T>
void free_in_parallel(std::vector<T>& v) {
  tbb::parallel_for(std::size_t{0}, v.size(), [&](std::size_t k) { T gone(std::move(v[k])); });
  std::vector<T>().swap(v);
}

/// The ids of the meshes read, one set a part (not merged: that would be a serial pass over every id).
using Delivered = std::vector<std::unordered_set<std::string>>;

/// Appends the parts (their footprints made) to the file's outcome, footprints and problems in reading
/// order, and empties them. The footprints are moved, and the parts freed, on every core: a city of 200k
/// buildings spent ~0.15 s of its 16-thread reading in a serial pass here (tests/bench/RESULTS.md,
/// "The serial steps around the parallel reading"). Only the slots that give a problem are visited
/// in order.
void append_parts(std::vector<Part>& parts, const std::string& file, FileRead& out, Delivered& delivered) {
  const std::size_t n = parts.size();
  // Per part: how many footprints it keeps, and the slots that say something (failed, or kept by a last resort).
  std::vector<std::size_t> first(n + 1, 0);
  struct Telling {
    std::size_t slot, kept_before;  // kept_before: where its footprint goes, counted from the part's first
  };
  std::vector<std::vector<Telling>> telling(n);
  tbb::parallel_for(std::size_t{0}, n, [&](std::size_t k) {
    std::size_t kept = 0, i = 0;
    for (const Part::Slot& slot : parts[k].slots) {
      if (!slot.fp.ok || !slot.fp.note.empty() || !slot.fp.misses_ground.empty()) telling[k].push_back({i, kept});
      if (slot.fp.ok) ++kept;
      ++i;
    }
    first[k + 1] = kept;
  });
  first[0] = out.footprints.size();
  for (std::size_t k = 0; k < n; ++k) first[k + 1] += first[k];
  out.footprints.resize(first[n]);
  tbb::parallel_for(std::size_t{0}, n, [&](std::size_t k) {
    std::size_t at = first[k];
    for (Part::Slot& slot : parts[k].slots) {
      if (!slot.fp.ok) continue;
      Footprint& f = slot.fp.footprint;
      f.source_file = file;
      f.method = to_string(slot.fp.method);
      out.footprints[at++] = std::move(f);
    }
  });
  for (std::size_t k = 0; k < n; ++k) {  // problems, in reading order
    Part& part = parts[k];
    std::size_t next = 0;  // next problem of part.problems to copy
    for (const Telling& t : telling[k]) {
      Part::Slot& slot = part.slots[t.slot];
      FootprintResult& fp = slot.fp;
      if (fp.ok) {  // kept (its footprint moved already), but found by a last resort: say why the earlier methods failed
        const std::string& id = out.footprints[first[k] + t.kept_before].source_id;
        if (!fp.note.empty())
          out.problems.push_back({id, file, "footprint",
                                  fp.method == FootprintMethod::DecompositionShadow ? "FOOTPRINT_SHADOW" : "FOOTPRINT_CLOSED_IN_PLAN",
                                  fp.note});
        // and a footprint that leaves out ground the building stands on (footprint/ground_check.h)
        if (!fp.misses_ground.empty()) out.problems.push_back({id, file, "footprint", "FOOTPRINT_MISSES_GROUND", fp.misses_ground});
        continue;
      }
      for (; next < slot.problem_pos; ++next) out.problems.push_back(std::move(part.problems[next]));
      if (!slot.collapsed.empty())  // the reader's geometry was fine: say what broke it, not "no GroundSurface"
        out.problems.push_back({fp.footprint.source_id, file, "georeference", "DEGENERATE_AFTER_GEOREFERENCING",
                                slot.collapsed + " (the footprint step found: " + fp.reason + ")"});
      else
        out.problems.push_back({fp.footprint.source_id, file, "footprint", fp.code, fp.reason});
      ++out.buildings_dropped;
    }
    for (; next < part.problems.size(); ++next) out.problems.push_back(std::move(part.problems[next]));
    out.buildings_read += part.buildings_read;
    out.buildings_dropped += part.buildings_dropped;
    delivered.push_back(std::move(part.delivered));
  }
  tbb::parallel_for(std::size_t{0}, n, [&](std::size_t k) { parts[k] = Part{}; });
}

/// The file's last words: buildings the reader gave up, notes, and the CRS facts for the pipeline.
void finish_file(FileRead& out, const Delivered& delivered, const ReadInfo& info, const Placer* placer,
                 const std::string& file, const PipelineOptions& options, const ReadContext& context) {
  const WorkingFrame* frame = placer ? placer->frame.get() : nullptr;
  // Buildings the reader gave up count as read and dropped: nothing is lost silently. Whatever the
  // format, such a building is named by a read-stage Problem and gave no mesh (a building that did
  // give one may have read-stage defects too: a dropped face, a missing xlink).
  auto was_delivered = [&](const std::string& id) {
    return std::any_of(delivered.begin(), delivered.end(), [&](const auto& set) { return set.count(id) > 0; });
  };
  std::unordered_set<std::string> given_up;
  for (const Problem& p : out.problems)
    if (p.stage == "read" && !p.source_id.empty() && p.code != "NOTE" && !given_up.count(p.source_id) &&
        !was_delivered(p.source_id))
      given_up.insert(p.source_id);
  out.buildings_read += given_up.size();
  out.buildings_dropped += given_up.size();
  out.delivered = std::any_of(delivered.begin(), delivered.end(), [](const auto& set) { return !set.empty(); });
  if (info.citygml.bytes_streamed) out.xml_streamed_why = info.citygml.streamed_why;
  if (info.in_working_crs) {
    if (!options.s_srs.empty())
      out.problems.push_back({"", file, "georeference", "NOTE",
                              "-s_srs/-a_srs " + options.s_srs + " is not used for this file: " +
                                  to_string(info.format) + " is georeferenced in WGS 84 by its own format"});
    for (const std::string& note : info.notes) out.problems.push_back({"", file, "georeference", "NOTE", note});
    out.in_working_crs = true;
    out.reader_crs = info.working_crs;
  }
  if (frame && placer->without_crs) {
    out.problems.push_back({"", file, "georeference", "NO_CRS",
                            no_crs_reason(file, no_crs_cause(placer->frame_srs), context.working_definition)});
  } else if (frame) {
    if (placer->srs_found_later)
      out.problems.push_back({"", file, "georeference", "NOTE",
                              "srsName \"" + placer->frame_srs.substr(0, 200) +
                                  "\" is written only after the file's first building (on another object's "
                                  "envelope): it holds for the whole file"});
    if (!options.s_srs.empty())
      out.problems.push_back({"", file, "georeference", "NOTE",
                              "source CRS " + options.s_srs + " from -s_srs/-a_srs (the file says \"" +
                                  info.citygml.srs_name.substr(0, 200) + "\")"});
    for (const std::string& note : frame->notes()) out.problems.push_back({"", file, "georeference", "NOTE", note});
    out.has_frame = true;
    out.frame_source_known = frame->source_known();
    out.frame_crs = frame->working_crs();
    out.frame_srs = placer->frame_srs;
  }
}

/// What read_any is told for a whole file.
ReadOptions whole_read_options(const PipelineOptions& options, const ReadContext& context) {
  ReadOptions read_options;
  read_options.lod = options.lod;
  read_options.lod_refinement = options.lod_refinement;
  read_options.origin = options.origin;
  read_options.ogr = options.ogr_input;
  read_options.gltf.id_field = options.ogr_input.id_field;  // glTF / 3D Tiles: the property naming a feature
  read_options.target_srs = context.working_definition;  // KML/glTF are placed by the reader, in this CRS
  return read_options;
}

/// The whole file, one building after the other (footprints on the other cores).
FileRead read_whole(const std::string& file, const PipelineOptions& options, const ReadContext& context,
                    ByteProgress& bytes) {
  FileRead out;
  Part part;
  ReadInfo info;
  ReadOptions read_options = whole_read_options(options, context);
  bool counted_bytes = false;
  read_options.on_bytes = [&](std::uint64_t n) {
    counted_bytes = true;
    bytes.add(n);
  };
  Placer placer(file, options, context, info.in_working_crs, info.citygml, {}, nullptr, &info);
  out.files_opened.push_back(file);
  {
    FootprintMaker maker(options, true);
    FilesHeard heard(out.files_opened);
    try {
      read_any(file, read_options, [&](Mesh&& mesh) {
        if (placer.place(mesh, part)) maker.add(std::move(mesh), part);
      }, part.problems, info);
    } catch (const Cancelled&) {
      throw;
    } catch (const InputError& e) {
      // One unreadable file does not stop the others; it is a problem of its own. Buildings read
      // before the fault stay (a truncated file).
      out.failed = true;
      out.failure = e.what();
      part.problems.push_back({"", file, "read", "UNREADABLE_FILE", e.what()});
    } catch (const InvalidArgument& e) {
      // The file's CRS cannot go to the working CRS (its srsName unknown while the first file, or
      // -t_srs, fixed one): the same, a problem of this file. A bad -t_srs fails every file, so the run.
      out.failed = true;
      out.failure = e.what();
      part.problems.push_back({"", file, "georeference", "UNREADABLE_FILE", e.what()});
    }
    const auto t_wait = std::chrono::steady_clock::now();
    maker.wait();
    out.footprint_wait_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_wait).count();
  }
  if (!counted_bytes) {
    VSIStatBufL st;
    if (VSIStatL(file.c_str(), &st) == 0) bytes.add(static_cast<std::uint64_t>(st.st_size));
  }
  Delivered delivered;
  std::vector<Part> parts(1);
  parts[0] = std::move(part);
  append_parts(parts, file, out, delivered);
  finish_file(out, delivered, info, &placer, file, options, context);
  return out;
}

/// The parts of one file (CityGML chunks, OGR feature ranges) read side by side, each into its Part,
/// georeferenced as the whole-file reading does.
struct SideBySide {
  std::vector<Part> parts;
  std::vector<std::unique_ptr<Placer>> placers;
  const Placer* first = nullptr;  // the part whose frame stands for the file's
  std::vector<std::vector<std::string>> opened;  // the files each part's reader opened (files_read.h)

  /// The file and what the parts opened, for FileRead::files_opened.
  std::vector<std::string> files_opened(const std::string& file) const {
    std::vector<std::string> all{file};
    for (const auto& o : opened) all.insert(all.end(), o.begin(), o.end());
    return all;
  }
};

/// Reads part k: its meshes to on_mesh, its problems to problems. Throws to say the parts are not the
/// whole-file reading.
using ReadPart = std::function<void(std::size_t k, const std::function<void(Mesh&&)>& on_mesh, std::vector<Problem>& problems)>;

/// Reads the parts (one per entry of `infos`, where each part's reader keeps what it learns: the srsName
/// read so far, the format's CRS) side by side; empty, or why they do not read the file as read_whole does.
std::string read_side_by_side(const std::string& file, const PipelineOptions& options, const ReadContext& context,
                              std::vector<ReadInfo>& infos, const ReadPart& read_part, SideBySide& s) {
  const std::size_t n = infos.size();
  s.parts.assign(n, Part{});
  s.placers.resize(n);
  s.opened.assign(n, {});
  std::vector<std::optional<std::string>> frame_srs(n);  // what each part's frame was made from, if it made one
  tbb::enumerable_thread_specific<Placer::Kept> kept;
  std::vector<std::string> errors(n);
  const bool in_working_crs = false;
  std::atomic<bool> failed{false};
  auto read_one = [&](std::size_t k, std::optional<std::array<double, 2>> decision, bool keep) {
    if (failed.load(std::memory_order_relaxed)) return;
    s.placers[k] = std::make_unique<Placer>(file, options, context, in_working_crs, infos[k].citygml, decision,
                                            keep ? &kept.local() : nullptr, &infos[k]);
    FootprintMaker maker(options, false);  // the parts keep every core busy already
    FilesHeard heard(s.opened[k]);
    try {
      read_part(k, [&](Mesh&& mesh) {
        if (s.placers[k]->place(mesh, s.parts[k])) maker.add(std::move(mesh), s.parts[k]);
      }, s.parts[k].problems);
    } catch (const Cancelled&) {
      throw;
    } catch (const std::exception& e) {
      errors[k] = e.what();
      failed = true;
    }
    if (s.placers[k]->frame) frame_srs[k] = s.placers[k]->frame_srs;
    if (keep) s.placers[k].reset();  // its frame goes back to the thread for its next part
  };
  // The parts before the first placed building, one by one: that building may fix the working CRS
  // (the UTM zone of its centre), which every part after it must use as the whole-file reading does.
  std::size_t k = 0;
  while (k < n && !failed) {
    read_one(k, {}, false);
    const Placer& p = *s.placers[k++];
    if (p.frame && !s.first) s.first = &p;
    if (p.frame && p.frame->decided()) {
      s.first = &p;
      break;
    }
  }
  const std::optional<std::array<double, 2>> decision = s.first ? s.first->decided_at : std::nullopt;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(k, n, 1), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) read_one(i, decision, true);
  }, tbb::simple_partitioner());
  for (std::size_t i = 0; i < n; ++i)
    if (!errors[i].empty()) return "part " + std::to_string(i + 1) + " of " + std::to_string(n) + ": " + errors[i];
  for (std::size_t i = 0; i < n; ++i)
    if (s.first && frame_srs[i] && *frame_srs[i] != s.first->frame_srs)
      return "the source CRS before the first building differs between parts";
  return {};
}

/// The chunks of `plan` side by side; nullopt (and `why`) when they do not read the file as
/// read_whole does.
std::optional<FileRead> read_chunks(const std::string& file, const CityGmlChunkPlan& plan,
                                    const PipelineOptions& options, const ReadContext& context, ByteProgress& bytes,
                                    std::string& why) {
  const std::size_t n = plan.ranges.size();
  std::vector<ReadInfo> infos(n);
  for (ReadInfo& info : infos) info.format = InputFormat::CityGml;  // what read_any says before its first mesh
  std::vector<CityGmlChunkWatch> watches(n);
  CityGmlOptions citygml;
  citygml.lod = options.lod;
  citygml.dom_max_bytes = citygml::in_memory_bytes();
  citygml.on_bytes = [&bytes](std::uint64_t b) { bytes.add(b); };
  SideBySide s;
  why = read_side_by_side(file, options, context, infos, [&](std::size_t k, const auto& on_mesh, auto& problems) {
    read_citygml_chunk(file, plan, k, citygml, on_mesh, problems, infos[k].citygml, watches[k]);
  }, s);
  if (!why.empty()) return std::nullopt;
  std::vector<SourceInfo> sources(n);
  for (std::size_t k = 0; k < n; ++k) sources[k] = infos[k].citygml;
  SourceInfo merged;
  std::vector<Problem> file_problems;
  why = merge_citygml_chunks(file, plan, sources, watches, merged, file_problems);
  if (!why.empty()) return std::nullopt;

  FileRead out;
  Delivered delivered;
  append_parts(s.parts, file, out, delivered);
  out.problems.insert(out.problems.end(), file_problems.begin(), file_problems.end());
  ReadInfo info;
  info.citygml = merged;
  info.format = InputFormat::CityGml;
  finish_file(out, delivered, info, s.first, file, options, context);
  out.files_opened = s.files_opened(file);
  out.chunks = n;
  free_in_parallel(delivered);  // ~400k ids between them
  free_in_parallel(watches);
  return out;
}

/// The feature ranges of `plan` side by side; nullopt (and `why`) when they do not read the source as
/// read_whole does.
std::optional<FileRead> read_ogr_ranges(const std::string& file, const OgrRangePlan& plan,
                                        const PipelineOptions& options, const ReadContext& context, ByteProgress& bytes,
                                        std::string& why) {
  const std::size_t n = plan.ranges.size();
  std::vector<ReadInfo> infos(n);
  for (ReadInfo& info : infos) {  // what read_any says of the source before its first mesh
    info.format = InputFormat::Ogr;
    info.source_srs = plan.source_srs;
    info.source_axis = plan.east_north ? AxisOrder::EastNorth : AxisOrder::NorthEast;
  }
  std::vector<OgrRangeWatch> watches(n);
  SideBySide s;
  why = read_side_by_side(file, options, context, infos, [&](std::size_t k, const auto& on_mesh, auto& problems) {
    read_ogr_range(file, options.ogr_input, plan, k, on_mesh, problems, watches[k]);
  }, s);
  if (why.empty()) why = check_ogr_ranges(plan, watches);
  if (!why.empty()) return std::nullopt;

  FileRead out;
  out.problems = plan.head;  // the whole reading says them before its first feature
  Delivered delivered;
  append_parts(s.parts, file, out, delivered);
  VSIStatBufL st;
  if (VSIStatL(file.c_str(), &st) == 0) bytes.add(static_cast<std::uint64_t>(st.st_size));
  finish_file(out, delivered, infos.front(), s.first, file, options, context);
  out.files_opened = s.files_opened(file);
  out.chunks = n;
  return out;
}

/// Bytes per chunk when `shared` bytes are read with `threads` threads: about four chunks a thread,
/// 2-8 MiB each. A chunk re-reads the file's head, and a thread should not wait on one huge chunk; a
/// chunk is parsed in memory (CityGmlOptions::dom_max_bytes), where its tree takes about its size again
/// and is walked after the parse: smaller chunks stay in the caches longer and hold less memory (16
/// threads on the 16-core host, 1.5 GB: read 1.2-1.3 s with 2-8 MiB, 1.45-1.55 s with 23 MiB; peak RSS
/// 611-881 MiB against 1558, tests/bench/RESULTS.md). On one thread a file is cut only when it is too
/// large to be parsed in memory whole, and in 32 MiB chunks: there each chunk's fixed cost showed
/// (1.5 GB on one thread: read 11.4 s in 46 chunks, 13.6 s in 180).
std::uint64_t auto_chunk_bytes(std::uint64_t shared, std::size_t threads) {
  if (threads <= 1) return std::uint64_t{32} << 20;
  const std::uint64_t per = shared / (4 * threads);
  return std::clamp<std::uint64_t>(per, std::uint64_t{2} << 20, std::uint64_t{8} << 20);
}

}  // namespace

std::string guess_working_definition(const std::string& file, const PipelineOptions& options,
                                     const ReadContext& context) {
  struct Decided {};  // thrown from the mesh callback: the reader stops there
  ReadInfo info;
  Part part;
  Placer placer(file, options, context, info.in_working_crs, info.citygml, {}, nullptr, &info);
  const auto on_mesh = [&](Mesh&& mesh) {
    placer.place(mesh, part);
    if (info.in_working_crs || (placer.frame && placer.frame->decided())) throw Decided{};
  };
  try {
    CityGmlChunkPlan plan;
    if (detect_format(file) == InputFormat::CityGml)
      plan = plan_citygml_chunks(file, std::uint64_t{4} << 20, std::uint64_t{1} << 20);
    if (plan.why_not.empty() && plan.ranges.size() >= 2) {
      // Its first chunk (the file's head and first buildings), read as read_chunks reads it.
      CityGmlOptions citygml;
      citygml.lod = options.lod;
      citygml.dom_max_bytes = citygml::in_memory_bytes();
      CityGmlChunkWatch watch;
      info.format = InputFormat::CityGml;  // as read_chunks and read_any say
      read_citygml_chunk(file, plan, 0, citygml, on_mesh, part.problems, info.citygml, watch);
    } else {
      read_any(file, whole_read_options(options, context), on_mesh, part.problems, info);
    }
  } catch (const Decided&) {
  } catch (const Cancelled&) {
    throw;
  } catch (const std::exception&) {
    return {};  // the reading of the file itself says what is wrong
  }
  if (info.in_working_crs || !placer.frame || !placer.frame->source_known() || !placer.frame->decided()) return {};
  const WorkingCrs& crs = placer.frame->working_crs();
  return crs.known ? crs.definition : std::string{};
}

std::string no_crs_cause(const std::string& srs) {
  const SrsName name = parse_srs_name(srs);
  if (srs.empty()) return "it names none (no srsName)";
  if (name.local) return "its srsName \"" + srs.substr(0, 200) + "\" is a CRS local to the file";
  return "its srsName \"" + srs.substr(0, 200) + "\" is no projected or geographic CRS PROJ knows";
}

std::string no_crs_reason(const std::string& file, const std::string& cause, const std::string& crs) {
  return file + " has no CRS (" + cause + "), but the other inputs are georeferenced (" + crs +
         "): its coordinates cannot be placed among theirs, so its buildings are left out (each a NO_CRS problem); "
         "process it on its own, naming its CRS with -s_srs (open option S_SRS; it applies to every input)";
}

void ByteProgress::add(std::uint64_t n) {
  const std::uint64_t done = done_.fetch_add(n, std::memory_order_relaxed) + n;
  if (!progress_ || done < next_report_.load(std::memory_order_relaxed)) return;
  std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock()) return;
  next_report_.store(done + total_ / 200 + 1, std::memory_order_relaxed);
  progress_.report(total_ ? std::min(1.0, static_cast<double>(done) / static_cast<double>(total_)) : 1.0, "reading");
}

FileRead read_file(const std::string& file, const PipelineOptions& options, const ReadContext& context,
                   std::size_t threads, std::uint64_t shared_bytes, ByteProgress& bytes) {
  std::string whole_reason;
  if (options.read_chunk_bytes >= 0 && detect_format(file) == InputFormat::CityGml) {
    VSIStatBufL st;
    const auto size = VSIStatL(file.c_str(), &st) == 0 ? static_cast<std::uint64_t>(st.st_size) : 0;
    // Cut for threads, or, on one thread, a file too large to be parsed in memory whole (citygml.h
    // dom_max_bytes): its chunks are parsed by pugixml where the file would be streamed through expat.
    const std::uint64_t in_memory = citygml::in_memory_bytes();
    if (size > 0 && (options.read_chunk_bytes > 0 || threads > 1 || (in_memory > 0 && size > in_memory))) {
      const std::uint64_t chunk = options.read_chunk_bytes > 0 ? static_cast<std::uint64_t>(options.read_chunk_bytes)
                                                               : auto_chunk_bytes(std::max(size, shared_bytes), threads);
      if (size >= 2 * chunk) {
        try {
          const CityGmlChunkPlan plan = plan_citygml_chunks(file, chunk, std::min<std::uint64_t>(chunk, 1 << 20));
          whole_reason = plan.why_not;
          if (plan.why_not.empty()) {
            std::optional<FileRead> chunked = read_chunks(file, plan, options, context, bytes, whole_reason);
            if (chunked) return std::move(*chunked);
          }
        } catch (const InputError& e) {
          whole_reason = e.what();  // read_whole says it again, as a problem of the file
        }
      }
    }
  }
  const bool may_range = options.read_chunk_bytes >= 0 && options.read_range_features >= 0 &&
                         (options.read_range_features > 0 || threads > 1);
  if (may_range && detect_format(file) == InputFormat::Unknown && ogr_can_read(file)) {
    try {
      const OgrRangePlan plan = plan_ogr_ranges(file, options.ogr_input, options.read_range_features, threads);
      whole_reason = plan.why_not;
      if (plan.ranges.size() >= 2) {
        std::optional<FileRead> ranged = read_ogr_ranges(file, plan, options, context, bytes, whole_reason);
        if (ranged) return std::move(*ranged);
      }
    } catch (const InputError& e) {
      whole_reason = e.what();  // read_whole says it again, as a problem of the file
    }
  }
  FileRead out = read_whole(file, options, context, bytes);
  out.whole_reason = std::move(whole_reason);
  return out;
}

}  // namespace groundplan::gis::detail
