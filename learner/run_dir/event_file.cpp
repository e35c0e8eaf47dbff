#include "learner/run_dir/event_file.hpp"

#include <array>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace masa::learner {
namespace fs = std::filesystem;

namespace {

// CRC-32C (Castagnoli, reflected polynomial 0x82f63b78), table-driven.
const std::array<uint32_t, 256>& crcTable() {
  static const std::array<uint32_t, 256> table = [] {
    std::array<uint32_t, 256> t{};
    for (uint32_t i = 0; i < 256; ++i) {
      uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? (c >> 1) ^ 0x82f63b78u : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  return table;
}

uint32_t crc32c(const void* data, std::size_t n) {
  const auto& t = crcTable();
  const auto* p = static_cast<const unsigned char*>(data);
  uint32_t c = 0xffffffffu;
  for (std::size_t i = 0; i < n; ++i) c = t[(c ^ p[i]) & 0xff] ^ (c >> 8);
  return c ^ 0xffffffffu;
}

uint32_t maskedCrc(const void* data, std::size_t n) {
  const uint32_t c = crc32c(data, n);
  return ((c >> 15) | (c << 17)) + 0xa282ead8u;
}

// --- protobuf wire format, the few pieces an Event needs

void varint(std::string& out, uint64_t v) {
  while (v >= 0x80) {
    out.push_back(static_cast<char>((v & 0x7f) | 0x80));
    v >>= 7;
  }
  out.push_back(static_cast<char>(v));
}
void key(std::string& out, int field, int wire_type) { varint(out, static_cast<uint64_t>(field) << 3 | wire_type); }
void bytesField(std::string& out, int field, const std::string& bytes) {
  key(out, field, 2);
  varint(out, bytes.size());
  out += bytes;
}
template <typename T>
void fixedField(std::string& out, int field, T v) {
  key(out, field, sizeof(T) == 8 ? 1 : 5);
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));  // little-endian, as the format is (x86, ARM)
  out.append(b, sizeof(T));
}

std::string event(double wall_time, int64_t step) {
  std::string e;
  fixedField(e, 1, wall_time);
  key(e, 2, 0);
  varint(e, static_cast<uint64_t>(step));
  return e;
}

double now() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

// --- reading

struct Reader {
  const std::string& b;
  std::size_t at, end;
  bool more() const { return at < end; }
  uint64_t varint() {
    uint64_t v = 0;
    for (int shift = 0; shift < 64; shift += 7) {
      if (at >= end) throw std::runtime_error("a varint runs past its message");
      const auto c = static_cast<unsigned char>(b[at++]);
      v |= static_cast<uint64_t>(c & 0x7f) << shift;
      if (!(c & 0x80)) return v;
    }
    throw std::runtime_error("a varint of more than 10 bytes");
  }
  template <typename T>
  T fixed() {
    if (end - at < sizeof(T)) throw std::runtime_error("a fixed field runs past its message");
    T v;
    std::memcpy(&v, b.data() + at, sizeof(T));
    at += sizeof(T);
    return v;
  }
  Reader sub() {
    const uint64_t n = varint();
    if (n > end - at) throw std::runtime_error("a field's length runs past its message");
    Reader r{b, at, at + n};
    at += n;
    return r;
  }
  void skip(int wire_type) {
    if (wire_type == 0) varint();
    else if (wire_type == 1) fixed<uint64_t>();
    else if (wire_type == 5) fixed<uint32_t>();
    else if (wire_type == 2) sub();
    else throw std::runtime_error("wire type " + std::to_string(wire_type) + " is not one an event has");
  }
};

std::string stringOf(Reader r) { return r.b.substr(r.at, r.end - r.at); }

void readValue(Reader r, EventRecord& out) {
  while (r.more()) {
    const uint64_t k = r.varint();
    const int field = static_cast<int>(k >> 3), wt = static_cast<int>(k & 7);
    if (field == 1 && wt == 2) out.tag = stringOf(r.sub());
    else if (field == 2 && wt == 5) {
      out.value = r.fixed<float>();
      out.is_scalar = true;
    } else if (field == 8 && wt == 2) {  // a tensor: its string_val (8) is the text
      Reader t = r.sub();
      while (t.more()) {
        const uint64_t tk = t.varint();
        if ((tk >> 3) == 8 && (tk & 7) == 2) out.text = stringOf(t.sub());
        else t.skip(static_cast<int>(tk & 7));
      }
    } else r.skip(wt);
  }
}

EventRecord parseEvent(const std::string& bytes) {
  EventRecord out;
  Reader r{bytes, 0, bytes.size()};
  while (r.more()) {
    const uint64_t k = r.varint();
    const int field = static_cast<int>(k >> 3), wt = static_cast<int>(k & 7);
    if (field == 1 && wt == 1) out.wall_time = r.fixed<double>();
    else if (field == 2 && wt == 0) out.step = static_cast<int64_t>(r.varint());
    else if (field == 3 && wt == 2) out.file_version = stringOf(r.sub());
    else if (field == 5 && wt == 2) {
      Reader summary = r.sub();
      while (summary.more()) {
        const uint64_t sk = summary.varint();
        if ((sk >> 3) == 1 && (sk & 7) == 2) readValue(summary.sub(), out);
        else summary.skip(static_cast<int>(sk & 7));
      }
    } else r.skip(wt);
  }
  return out;
}

}  // namespace

EventFile::EventFile(const std::string& dir) : path_((fs::path(dir) / kFileName).string()) {
  const bool fresh = !fs::exists(path_) || fs::file_size(path_) == 0;
  file_ = std::fopen(path_.c_str(), "ab");
  if (!file_) throw std::runtime_error(path_ + ": cannot write the TensorBoard event file");
  if (fresh) {
    std::string e = event(now(), 0);
    bytesField(e, 3, "brain.Event:2");
    record(e);
  }
}

EventFile::~EventFile() {
  if (file_) std::fclose(file_);
}

void EventFile::record(const std::string& e) {
  char header[12];
  const uint64_t n = e.size();
  std::memcpy(header, &n, 8);
  const uint32_t header_crc = maskedCrc(header, 8), data_crc = maskedCrc(e.data(), e.size());
  std::memcpy(header + 8, &header_crc, 4);
  std::string r(header, 12);
  r += e;
  r.append(reinterpret_cast<const char*>(&data_crc), 4);
  // One write and a flush per record: a killed run leaves whole records (and at most a torn last one).
  if (std::fwrite(r.data(), 1, r.size(), file_) != r.size() || std::fflush(file_) != 0)
    throw std::runtime_error(path_ + ": cannot append to the TensorBoard event file");
}

void EventFile::scalar(const std::string& tag, int64_t step, double value, double wall_time) {
  std::string v;
  bytesField(v, 1, tag);
  fixedField(v, 2, static_cast<float>(value));
  std::string summary;
  bytesField(summary, 1, v);
  std::string e = event(wall_time > 0 ? wall_time : now(), step);
  bytesField(e, 5, summary);
  record(e);
}

void EventFile::text(const std::string& tag, int64_t step, const std::string& markdown, double wall_time) {
  std::string plugin, metadata, tensor, v, summary;
  bytesField(plugin, 1, "text");  // PluginData.plugin_name
  bytesField(metadata, 1, plugin);  // SummaryMetadata.plugin_data
  key(tensor, 1, 0);
  varint(tensor, 7);  // dtype: DT_STRING
  bytesField(tensor, 2, "");  // tensor_shape: a scalar
  bytesField(tensor, 8, markdown);  // string_val
  bytesField(v, 1, tag);
  bytesField(v, 9, metadata);
  bytesField(v, 8, tensor);
  bytesField(summary, 1, v);
  std::string e = event(wall_time > 0 ? wall_time : now(), step);
  bytesField(e, 5, summary);
  record(e);
}

std::string preformatted(const std::string& text) {
  std::string out = "    ";
  for (char c : text) out += c == '\n' ? std::string("\n    ") : std::string(1, c);
  return out;
}

EventFileContents readEventFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot read");
  const std::string b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EventFileContents out;
  std::size_t at = 0;
  while (at < b.size()) {
    if (b.size() - at < 12) {
      out.torn_tail = true;
      break;
    }
    uint64_t n;
    uint32_t header_crc;
    std::memcpy(&n, b.data() + at, 8);
    std::memcpy(&header_crc, b.data() + at + 8, 4);
    if (header_crc != maskedCrc(b.data() + at, 8))
      throw std::runtime_error(path + ": the record at byte " + std::to_string(at) + " has a damaged length (CRC)");
    if (n > b.size() - at - 12 || b.size() - at - 12 - n < 4) {
      out.torn_tail = true;
      break;
    }
    uint32_t data_crc;
    std::memcpy(&data_crc, b.data() + at + 12 + n, 4);
    if (data_crc != maskedCrc(b.data() + at + 12, n))
      throw std::runtime_error(path + ": the record at byte " + std::to_string(at) + " is damaged (CRC)");
    try {
      out.records.push_back(parseEvent(b.substr(at + 12, n)));
    } catch (const std::runtime_error& e) {
      throw std::runtime_error(path + ": the record at byte " + std::to_string(at) + " is not an event: " + e.what());
    }
    at += 12 + n + 4;
    out.ends.push_back(at);
  }
  return out;
}

void truncateEventFile(const std::string& path, int64_t last_step) {
  if (!fs::exists(path)) return;
  const EventFileContents c = readEventFile(path);
  uint64_t keep = 0;
  for (std::size_t i = 0; i < c.records.size() && c.records[i].step <= last_step; ++i) keep = c.ends[i];
  if (keep != fs::file_size(path)) fs::resize_file(path, keep);
}

}  // namespace masa::learner
