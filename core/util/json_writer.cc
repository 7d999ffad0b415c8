#include "core/util/json_writer.h"

#include <fmt/format.h>

#include <cmath>

#include "core/util/error.h"

namespace pkslam {

std::string JsonQuote(std::string_view text) {
  std::string out;
  out.reserve(text.size() + 2);
  out.push_back('"');
  for (const char c : text) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\b':
        out += "\\b";
        break;
      case '\f':
        out += "\\f";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\r':
        out += "\\r";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          out += fmt::format("\\u{:04x}", static_cast<unsigned>(static_cast<unsigned char>(c)));
        } else {
          out.push_back(c);  // printable ASCII and UTF-8 bytes pass through unchanged
        }
    }
  }
  out.push_back('"');
  return out;
}

JsonWriter::JsonWriter(int indent) : indent_(indent) {
  PKSLAM_CHECK(indent >= 0, "negative JSON indent {}", indent);
}

void JsonWriter::NewlineAndIndent(std::size_t depth) {
  if (indent_ == 0) return;
  out_.push_back('\n');
  out_.append(depth * static_cast<std::size_t>(indent_), ' ');
}

void JsonWriter::BeforeValue(std::string_view what) {
  if (stack_.empty()) {
    PKSLAM_CHECK(!root_written_, "JSON: {} after the complete top-level value", what);
    root_written_ = true;
    return;
  }
  Level& level = stack_.back();
  if (level.scope == Scope::kObject) {
    PKSLAM_CHECK(key_pending_, "JSON: {} inside an object without a Key()", what);
    key_pending_ = false;
    return;  // Key() already wrote the separator and indentation
  }
  if (level.members > 0) out_.push_back(',');
  NewlineAndIndent(stack_.size());
  ++level.members;
}

JsonWriter& JsonWriter::Key(std::string_view key) {
  PKSLAM_CHECK(!stack_.empty() && stack_.back().scope == Scope::kObject,
               "JSON: Key(\"{}\") outside an object", key);
  PKSLAM_CHECK(!key_pending_, "JSON: Key(\"{}\") after a Key() without a value", key);
  Level& level = stack_.back();
  if (level.members > 0) out_.push_back(',');
  NewlineAndIndent(stack_.size());
  ++level.members;
  out_ += JsonQuote(key);
  out_ += indent_ > 0 ? ": " : ":";
  key_pending_ = true;
  return *this;
}

JsonWriter& JsonWriter::BeginObject() {
  BeforeValue("BeginObject()");
  out_.push_back('{');
  stack_.push_back({Scope::kObject, 0});
  return *this;
}

JsonWriter& JsonWriter::EndObject() {
  PKSLAM_CHECK(!stack_.empty() && stack_.back().scope == Scope::kObject,
               "JSON: EndObject() without a matching BeginObject()");
  PKSLAM_CHECK(!key_pending_, "JSON: EndObject() right after a Key()");
  const bool had_members = stack_.back().members > 0;
  stack_.pop_back();
  if (had_members) NewlineAndIndent(stack_.size());
  out_.push_back('}');
  return *this;
}

JsonWriter& JsonWriter::BeginArray() {
  BeforeValue("BeginArray()");
  out_.push_back('[');
  stack_.push_back({Scope::kArray, 0});
  return *this;
}

JsonWriter& JsonWriter::EndArray() {
  PKSLAM_CHECK(!stack_.empty() && stack_.back().scope == Scope::kArray,
               "JSON: EndArray() without a matching BeginArray()");
  const bool had_members = stack_.back().members > 0;
  stack_.pop_back();
  if (had_members) NewlineAndIndent(stack_.size());
  out_.push_back(']');
  return *this;
}

JsonWriter& JsonWriter::Value(double value) {
  if (!std::isfinite(value)) return Null();
  BeforeValue("a number");
  // fmt's default format is the shortest representation that round-trips, e.g. 0.1, 1e-05.
  out_ += fmt::format("{}", value);
  return *this;
}

JsonWriter& JsonWriter::Value(std::int64_t value) {
  BeforeValue("a number");
  out_ += fmt::format("{}", value);
  return *this;
}

JsonWriter& JsonWriter::Value(std::uint64_t value) {
  BeforeValue("a number");
  out_ += fmt::format("{}", value);
  return *this;
}

JsonWriter& JsonWriter::Value(bool value) {
  BeforeValue("a boolean");
  out_ += value ? "true" : "false";
  return *this;
}

JsonWriter& JsonWriter::Value(std::string_view value) {
  BeforeValue("a string");
  out_ += JsonQuote(value);
  return *this;
}

JsonWriter& JsonWriter::Null() {
  BeforeValue("null");
  out_ += "null";
  return *this;
}

bool JsonWriter::complete() const { return root_written_ && stack_.empty(); }

std::string JsonWriter::str() const {
  PKSLAM_CHECK(complete(), "JSON document incomplete ({} open scope(s))", stack_.size());
  return indent_ > 0 ? out_ + "\n" : out_;
}

}  // namespace pkslam
