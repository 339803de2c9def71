// Streamed report text at the speed of the disk: events are formatted into one large
// reusable buffer, written to the stream in big chunks, with no allocation per event and
// no stream call per field. Internal to collision_lab_io.
#pragma once

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <ostream>
#include <string_view>
#include <vector>

#include "collision_lab/io/number_text.h"

namespace collision_lab {
namespace io {

/// The text of recently printed doubles, by bit pattern (a small direct-mapped table).
/// Consecutive events repeat most of their values (the velocities before are the last
/// ones after, a body outside the impact keeps its value, paired energy transfers differ
/// only in sign), so most numbers are copied instead of converted. The text is exactly
/// what `format` gives.
class NumberTextCache {
 public:
  using Format = char* (*)(char*, double);

  explicit NumberTextCache(Format format) : format_(format) {
    Entry zero;
    zero.size = static_cast<std::uint8_t>(format(zero.text, 0.0) - zero.text);
    entries_.fill(zero);  // bits 0 is +0.0, so every entry starts valid
  }

  /// Writes the text of `value` at `out` (kNumberTextMax bytes of room); returns the end.
  char* write(char* out, double value) {
    if (std::isfinite(value) && value < 0) {  // -x is '-' and the text of x
      *out++ = '-';
      value = -value;
    }
    std::uint64_t bits;
    std::memcpy(&bits, &value, sizeof bits);
    Entry& entry = entries_[(bits * 0x9E3779B97F4A7C15ull) >> (64 - kLogSize)];
    if (entry.bits != bits) {
      entry.bits = bits;
      entry.size = static_cast<std::uint8_t>(format_(entry.text, value) - entry.text);
    }
    std::memcpy(out, entry.text, kNumberTextMax);
    return out + entry.size;
  }

 private:
  static constexpr int kLogSize = 8;
  struct Entry {
    std::uint64_t bits = 0;
    std::uint8_t size = 0;
    char text[kNumberTextMax] = {};
  };
  Format format_;
  std::array<Entry, std::size_t{1} << kLogSize> entries_;
};

/// Text gathered in a buffer and written to `out` in chunks of about kChunk bytes.
/// Call flushIfFull() after each event and flush() before writing to `out` directly.
/// With auto_flush false the buffer grows instead and only flush() writes (a block of
/// events formatted ahead of its turn); it keeps its size, so it allocates only at first.
class TextSink {
 public:
  static constexpr std::size_t kChunk = std::size_t{1} << 18;

  explicit TextSink(std::ostream& out, bool auto_flush = true)
      : out_(out), auto_flush_(auto_flush), buffer_(new char[kChunk + kSlack]), capacity_(kChunk + kSlack),
        csv_(writeCsvNumber), json_(writeJsonNumber) {}
  ~TextSink() { flush(); }
  TextSink(const TextSink&) = delete;
  TextSink& operator=(const TextSink&) = delete;

  void put(char c) {
    room(1);
    buffer_[size_++] = c;
  }
  void put(std::string_view text) {
    room(text.size());
    std::memcpy(at(), text.data(), text.size());
    size_ += text.size();
  }
  void count(std::uint64_t value) {
    room(24);
    size_ = static_cast<std::size_t>(std::to_chars(at(), at() + 24, value).ptr - buffer_.get());
  }
  /// writeCsvNumber's text.
  void csvNumber(double value) {
    room(kNumberTextMax + 1);
    size_ = static_cast<std::size_t>(csv_.write(at(), value) - buffer_.get());
  }
  /// writeJsonNumber's text.
  void jsonNumber(double value) {
    room(kNumberTextMax + 1);
    size_ = static_cast<std::size_t>(json_.write(at(), value) - buffer_.get());
  }

  /// `key` (e.g. ",\"time\":") and the value as jsonNumber.
  void jsonField(std::string_view key, double value) {
    put(key);
    jsonNumber(value);
  }
  /// `key` and the values (an indexable of size() doubles) as a JSON array.
  template <class Values>
  void jsonArray(std::string_view key, const Values& values) {
    put(key);
    put('[');
    for (std::size_t i = 0; i < values.size(); ++i) {
      if (i > 0) put(',');
      jsonNumber(values[i]);
    }
    put(']');
  }

  void flushIfFull() {
    if (size_ >= kChunk) flush();
  }
  void flush() {
    if (size_ > 0) out_.write(buffer_.get(), static_cast<std::streamsize>(size_));
    size_ = 0;
  }
  /// Drops the text not yet written (after a failure, so that it is never written late).
  void discard() { size_ = 0; }

 private:
  static constexpr std::size_t kSlack = std::size_t{1} << 16;

  char* at() { return buffer_.get() + size_; }
  void room(std::size_t bytes) {
    if (size_ + bytes <= capacity_) return;
    if (auto_flush_) flush();
    if (size_ + bytes <= capacity_) return;
    capacity_ = std::max(2 * capacity_, size_ + bytes);
    std::unique_ptr<char[]> grown(new char[capacity_]);
    std::memcpy(grown.get(), buffer_.get(), size_);
    buffer_ = std::move(grown);
  }

  std::ostream& out_;
  bool auto_flush_;
  // Not zeroed (new char[], not a vector): a small report touches only the pages it
  // writes, which makes a run's report cheap for callers that run many small scenes.
  std::unique_ptr<char[]> buffer_;
  std::size_t capacity_;
  std::size_t size_ = 0;
  NumberTextCache csv_;
  NumberTextCache json_;
};

}  // namespace io
}  // namespace collision_lab
