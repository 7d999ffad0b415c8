// A small streaming JSON writer for result files (eval results, stats.json, run summaries).
//
// The writer checks the document structure as it goes (a value inside an object needs a Key
// first, Begin/End must pair up, one top-level value) and throws pkslam::Error on misuse, so a
// malformed file is a programming error caught in tests, never silently written.
// Strings are escaped per RFC 8259 (quote, backslash, control characters as \uXXXX; UTF-8 is
// passed through). Doubles are written in the shortest form that reads back to the same value;
// NaN and infinities, which JSON cannot represent, are written as null.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace pkslam {

// `text` as a JSON string literal, including the surrounding quotes.
std::string JsonQuote(std::string_view text);

class JsonWriter {
 public:
  // indent > 0 pretty-prints with that many spaces per level; 0 writes one compact line.
  explicit JsonWriter(int indent = 2);

  JsonWriter& BeginObject();
  JsonWriter& EndObject();
  JsonWriter& BeginArray();
  JsonWriter& EndArray();
  // The key of the next member; only valid directly inside an object.
  JsonWriter& Key(std::string_view key);

  JsonWriter& Value(double value);
  JsonWriter& Value(std::int64_t value);
  JsonWriter& Value(std::uint64_t value);
  JsonWriter& Value(int value) { return Value(static_cast<std::int64_t>(value)); }
  JsonWriter& Value(bool value);
  JsonWriter& Value(std::string_view value);
  JsonWriter& Value(const char* value) { return Value(std::string_view(value)); }
  JsonWriter& Null();

  // Key(key).Value(value) in one call.
  template <typename T>
  JsonWriter& Member(std::string_view key, const T& value) {
    Key(key);
    return Value(value);
  }

  // True once exactly one complete top-level value has been written.
  bool complete() const;
  // The document (with a trailing newline when pretty-printing); throws if incomplete.
  std::string str() const;

 private:
  enum class Scope { kObject, kArray };
  struct Level {
    Scope scope;
    std::size_t members = 0;
  };

  // Writes separators/indentation before a value and checks that a value may go here.
  void BeforeValue(std::string_view what);
  void NewlineAndIndent(std::size_t depth);

  int indent_ = 2;
  std::string out_;
  std::vector<Level> stack_;
  bool key_pending_ = false;
  bool root_written_ = false;
};

}  // namespace pkslam
