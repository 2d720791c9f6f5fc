// SPDX-License-Identifier: MIT
// PlanSpill: a flat binary record a tile plan, length-prefixed (u64), host layout: the file lives only as long
// as the process that wrote it, and the ranks of an MPI run (issue 15) that exchange records run on hosts of one
// architecture.
#include "pipeline/plan_spill.h"

#include "pipeline/byte_reader.h"

#include <groundplan/error.h>

#include <cpl_conv.h>
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>

namespace groundplan::gis::detail {
namespace {

constexpr std::size_t kBufferBytes = 8u << 20;

class Writer {
 public:
  explicit Writer(std::vector<char>& out) : out_(out) {}
  template <class T>
  void put(const T& v) {
    const char* p = reinterpret_cast<const char*>(&v);
    out_.insert(out_.end(), p, p + sizeof(T));
  }
  void str(const std::string& s) {
    put(static_cast<std::uint32_t>(s.size()));
    out_.insert(out_.end(), s.begin(), s.end());
  }
  void ring(const Ring& r) {
    put(static_cast<std::uint32_t>(r.size()));
    for (const Point2& p : r) {
      put(p.x);
      put(p.y);
    }
  }
  void polygon(const Polygon& poly) {
    put(static_cast<std::uint32_t>(poly.holes.size()));
    ring(poly.outer);
    for (const Ring& h : poly.holes) ring(h);
  }

 private:
  std::vector<char>& out_;
};

class Reader : public ByteReader {
 public:
  Reader(const char* p, std::size_t n)
      : ByteReader(p, n, "tiled run: temporary plan file is corrupt (short record)") {}
  std::string str() { return ByteReader::str<std::uint32_t>(); }
  Ring ring(bool keep) {
    const auto n = get<std::uint32_t>();
    need(std::size_t{n} * 16);
    Ring r;
    if (keep) {
      r.resize(n);
      for (std::uint32_t i = 0; i < n; ++i) {
        std::memcpy(&r[i].x, p_ + 16 * i, 8);
        std::memcpy(&r[i].y, p_ + 16 * i + 8, 8);
      }
    }
    p_ += std::size_t{n} * 16;
    return r;
  }
  Polygon polygon(bool keep) {
    Polygon poly;
    const auto holes = get<std::uint32_t>();
    poly.outer = ring(keep);
    for (std::uint32_t h = 0; h < holes; ++h) {
      Ring r = ring(keep);
      if (keep) poly.holes.push_back(std::move(r));
    }
    return poly;
  }
};

std::string temp_directory() {
  if (const char* d = CPLGetConfigOption("CPL_TMPDIR", nullptr)) return d;
  if (const char* d = std::getenv("TMPDIR"); d && *d) return d;
  return "/tmp";
}

void read_fully(int fd, char* p, std::size_t n, std::uint64_t at) {
  while (n > 0) {
    const ssize_t got = ::pread(fd, p, n, static_cast<off_t>(at));
    if (got <= 0) {
      if (got < 0 && errno == EINTR) continue;
      throw Error(std::string("tiled run: cannot read back the temporary plan file: ") +
                  (got < 0 ? std::strerror(errno) : "unexpected end"));
    }
    p += got;
    n -= static_cast<std::size_t>(got);
    at += static_cast<std::uint64_t>(got);
  }
}

}  // namespace

PlanSpill::PlanSpill() : dir_(temp_directory()) {
  std::string path = dir_ + "/groundplan-tiles-XXXXXX";
  fd_ = ::mkstemp(path.data());
  if (fd_ < 0)
    throw Error("tiled run: cannot create a temporary file in " + dir_ + " (set CPL_TMPDIR or TMPDIR): " +
                std::strerror(errno));
  ::unlink(path.c_str());  // gone with the process, whatever happens
  buffer_.reserve(kBufferBytes + (1u << 20));
}

PlanSpill::~PlanSpill() {
  if (fd_ >= 0) ::close(fd_);
}

void PlanSpill::encode(const GroundPlan& plan, const std::vector<const Footprint*>& members, std::uint32_t tile,
                       const std::array<double, 4>& box, std::vector<char>& out) {
  const std::size_t start = out.size();
  Writer w(out);
  w.put(std::uint64_t{0});  // record length, filled below
  w.put(tile);
  for (double b : box) w.put(b);
  w.put(plan.area_m2);
  w.polygon(plan.polygon);
  w.put(static_cast<std::uint32_t>(plan.members.size()));
  for (std::size_t k = 0; k < plan.members.size(); ++k) {
    const Footprint& fp = *members[k];
    w.put(plan.members[k]);
    w.str(fp.source_id);
    w.str(fp.parent_id);
    w.str(fp.source_file);
    w.str(fp.method);
    w.put(fp.min_z);
    w.put(fp.max_z);
    w.put(static_cast<std::uint32_t>(fp.polygons.size()));
    for (const Polygon& p : fp.polygons) w.polygon(p);
  }
  const std::uint64_t length = out.size() - start - sizeof(std::uint64_t);
  std::memcpy(out.data() + start, &length, sizeof length);
}

std::uint64_t PlanSpill::append(const GroundPlan& plan, const std::vector<const Footprint*>& members,
                                std::uint32_t tile, const std::array<double, 4>& box) {
  const std::uint64_t offset = size_;
  const std::size_t start = buffer_.size();
  encode(plan, members, tile, box, buffer_);
  size_ += buffer_.size() - start;
  if (buffer_.size() >= kBufferBytes) flush();
  return offset;
}

std::uint64_t PlanSpill::append_encoded(const char* record, std::size_t n) {
  const std::uint64_t offset = size_;
  buffer_.insert(buffer_.end(), record, record + n);
  size_ += n;
  if (buffer_.size() >= kBufferBytes) flush();
  return offset;
}

std::size_t PlanSpill::record_length(const char* p, std::size_t left) {
  std::uint64_t length = 0;
  if (left < sizeof length) throw Error("tiled run: plan record cut short (length)");
  std::memcpy(&length, p, sizeof length);
  if (length > left - sizeof length) throw Error("tiled run: plan record cut short");
  return static_cast<std::size_t>(sizeof length + length);
}

void PlanSpill::flush() {
  std::size_t done = 0;
  while (done < buffer_.size()) {
    const ssize_t n = ::pwrite(fd_, buffer_.data() + done, buffer_.size() - done, static_cast<off_t>(written_));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0)
      throw Error("tiled run: cannot write the temporary plan file in " + dir_ + " (disk full? set CPL_TMPDIR): " +
                  std::strerror(errno));
    done += static_cast<std::size_t>(n);
    written_ += static_cast<std::uint64_t>(n);
  }
  buffer_.clear();
}

namespace {

SpilledPlan decode(Reader& r, bool polygons) {
  SpilledPlan s;
  s.tile = r.get<std::uint32_t>();
  for (double& b : s.box) b = r.get<double>();
  s.plan.area_m2 = r.get<double>();
  s.plan.polygon = r.polygon(true);
  const auto n = r.get<std::uint32_t>();
  s.ids.resize(n);
  s.footprints.resize(n);
  for (std::uint32_t k = 0; k < n; ++k) {
    Footprint& fp = s.footprints[k];
    s.ids[k] = r.get<std::uint32_t>();
    fp.source_id = r.str();
    fp.parent_id = r.str();
    fp.source_file = r.str();
    fp.method = r.str();
    fp.min_z = r.get<double>();
    fp.max_z = r.get<double>();
    const auto polys = r.get<std::uint32_t>();
    for (std::uint32_t p = 0; p < polys; ++p) {
      Polygon poly = r.polygon(polygons);
      if (polygons) fp.polygons.push_back(std::move(poly));
    }
  }
  s.plan.members = s.ids;
  return s;
}

}  // namespace

SpilledPlan PlanSpill::read(std::uint64_t offset, bool polygons, std::uint64_t* next) const {
  if (offset + sizeof(std::uint64_t) > written_) throw Error("tiled run: plan record past the end of the temporary file");
  std::uint64_t length = 0;
  read_fully(fd_, reinterpret_cast<char*>(&length), sizeof length, offset);
  if (offset + sizeof length + length > written_) throw Error("tiled run: temporary plan file is corrupt (length)");
  std::vector<char> bytes(length);
  read_fully(fd_, bytes.data(), length, offset + sizeof length);
  if (next) *next = offset + sizeof length + length;
  Reader r(bytes.data(), bytes.size());
  SpilledPlan s = decode(r, polygons);
  if (!r.done()) throw Error("tiled run: temporary plan file is corrupt (record longer than its contents)");
  return s;
}

std::vector<SpilledPlan> PlanSpill::decode_all(const std::vector<char>& bytes, bool polygons) {
  std::vector<SpilledPlan> out;
  for (std::size_t at = 0; at < bytes.size();) {
    const std::size_t n = record_length(bytes.data() + at, bytes.size() - at);
    Reader r(bytes.data() + at + sizeof(std::uint64_t), n - sizeof(std::uint64_t));
    out.push_back(decode(r, polygons));
    if (!r.done()) throw Error("tiled run: plan record longer than its contents");
    at += n;
  }
  return out;
}

}  // namespace groundplan::gis::detail
