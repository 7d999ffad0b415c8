// DBoW2 text format (ORBvoc.txt), as written by DBoW2 / ORB-SLAM's saveToTextFile:
//   line 1:      "k L  scoring weighting"           e.g. "10 6  0 0"
//   line i + 1:  "parent isLeaf b0 b1 ... b31  weight" for node i = 1..N-1 (root 0 implicit)
// Bytes are decimal 0..255 (OpenCV's byte order), weights as C++ streams print a double.
// Reading accepts any spaces/tabs and CRLF endings; writing reproduces DBoW2's spacing.
#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "core/bow/vocabulary.h"
#include "core/bow/vocabulary_internal.h"
#include "core/util/error.h"
#include "core/util/output_file.h"

namespace pkslam {
namespace {

// Splits a line into whitespace-separated tokens (at most max_tokens + 1, to detect extras).
std::size_t Tokenize(std::string_view line, std::string_view* tokens, std::size_t max_tokens) {
  std::size_t n = 0;
  std::size_t i = 0;
  while (i < line.size() && n <= max_tokens) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    if (i == line.size()) break;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (n == max_tokens) return max_tokens + 1;
    tokens[n++] = line.substr(start, i - start);
  }
  return n;
}

template <typename T>
bool ParseNumber(std::string_view token, T* value) {
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, *value);
  return ec == std::errc() && ptr == end;
}

std::string ReadWholeFile(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file, "cannot open vocabulary file");
  std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw InputError(file, "read error");
  return data;
}

// Next line of `data` from `pos` (without the newline and a trailing '\r'); false at the end.
bool NextLine(const std::string& data, std::size_t* pos, std::string_view* line) {
  if (*pos >= data.size()) return false;
  std::size_t end = data.find('\n', *pos);
  if (end == std::string::npos) end = data.size();
  std::size_t stop = end;
  if (stop > *pos && data[stop - 1] == '\r') --stop;
  *line = std::string_view(data).substr(*pos, stop - *pos);
  *pos = end + 1;
  return true;
}

bool IsBlank(std::string_view line) {
  return line.find_first_not_of(" \t") == std::string_view::npos;
}

VocabularyParams ParseHeader(const std::filesystem::path& file, std::string_view line) {
  std::string_view tok[4];
  if (Tokenize(line, tok, 4) != 4) {
    throw InputError(file, 1, "header must be 'k L scoring weighting' (4 integers)");
  }
  int v[4];
  for (int i = 0; i < 4; ++i) {
    if (!ParseNumber(tok[i], &v[i])) {
      throw InputError(file, 1, fmt::format("header field '{}' is not an integer", tok[i]));
    }
  }
  VocabularyParams params;
  params.branching = v[0];
  params.levels = v[1];
  params.scoring = static_cast<Scoring>(v[2]);
  params.weighting = static_cast<Weighting>(v[3]);
  if (auto problem = bow_internal::ParamsProblem(params)) throw InputError(file, 1, *problem);
  return params;
}

VocabularyNode ParseNode(const std::filesystem::path& file, std::size_t line_number,
                         std::string_view line) {
  constexpr std::size_t kTokens = 35;  // parent, leaf flag, 32 bytes, weight
  std::string_view tok[kTokens];
  const std::size_t n = Tokenize(line, tok, kTokens);
  if (n != kTokens) {
    throw InputError(file, line_number,
                     fmt::format("expected 35 fields 'parent isLeaf b0..b31 weight', found {}",
                                 n > kTokens ? "more" : std::to_string(n)));
  }
  VocabularyNode node;
  if (!ParseNumber(tok[0], &node.parent)) {
    throw InputError(file, line_number, fmt::format("bad parent id '{}'", tok[0]));
  }
  int leaf = 0;
  if (!ParseNumber(tok[1], &leaf) || (leaf != 0 && leaf != 1)) {
    throw InputError(file, line_number, fmt::format("leaf flag '{}' is not 0 or 1", tok[1]));
  }
  node.is_leaf = leaf == 1;
  for (int b = 0; b < 32; ++b) {
    unsigned value = 0;
    if (!ParseNumber(tok[2 + b], &value) || value > 255) {
      throw InputError(file, line_number,
                       fmt::format("descriptor byte {} '{}' is not in 0..255", b, tok[2 + b]));
    }
    node.descriptor.bytes[b] = static_cast<std::uint8_t>(value);
  }
  if (!ParseNumber(tok[34], &node.weight) || !std::isfinite(node.weight)) {
    throw InputError(file, line_number, fmt::format("bad weight '{}'", tok[34]));
  }
  return node;
}

void AppendUnsigned(std::string* out, unsigned value) {
  char buf[16];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof(buf), value);
  out->append(buf, end);
}

}  // namespace

namespace bow_internal {

std::string FormatWeight(double weight) {
  char buf[64];
  auto [end, ec] = std::to_chars(buf, buf + sizeof(buf), weight, std::chars_format::general, 6);
  double back = 0.0;
  std::from_chars(buf, end, back);
  if (back == weight && std::signbit(back) == std::signbit(weight)) return std::string(buf, end);
  end = std::to_chars(buf, buf + sizeof(buf), weight).ptr;  // shortest exact
  return std::string(buf, end);
}

}  // namespace bow_internal

Vocabulary Vocabulary::LoadText(const std::filesystem::path& file) {
  const std::string data = ReadWholeFile(file);
  std::size_t pos = 0;
  std::string_view line;
  if (!NextLine(data, &pos, &line) || IsBlank(line)) {
    throw InputError(file, 1, "empty vocabulary file (expected header 'k L scoring weighting')");
  }
  const VocabularyParams params = ParseHeader(file, line);

  std::vector<VocabularyNode> nodes;
  nodes.reserve(data.size() / 100 + 1);
  nodes.emplace_back();  // root
  std::size_t line_number = 1;
  std::size_t blank_line = 0;
  while (NextLine(data, &pos, &line)) {
    ++line_number;
    if (IsBlank(line)) {
      if (blank_line == 0) blank_line = line_number;
      continue;
    }
    if (blank_line != 0) {
      throw InputError(file, blank_line, "blank line inside the node list");
    }
    nodes.push_back(ParseNode(file, line_number, line));
  }
  if (auto problem = bow_internal::FindTreeProblem(params, nodes)) {
    // Node i is on line i + 1; problems of the whole tree are reported at the header.
    throw InputError(file, problem->node == 0 ? 1 : problem->node + 1, problem->message);
  }
  return FromValidNodes(params, std::move(nodes));
}

void Vocabulary::SaveText(const std::filesystem::path& file) const {
  PKSLAM_CHECK(!empty(), "cannot save an empty vocabulary to {}", file.string());
  std::string out;
  out.reserve(node_count() * 120 + 32);
  out += fmt::format("{} {}  {} {}\n", params_.branching, params_.levels,
                     static_cast<int>(params_.scoring), static_cast<int>(params_.weighting));
  const std::vector<VocabularyNode> nodes = Nodes();
  for (std::size_t i = 1; i < nodes.size(); ++i) {
    const VocabularyNode& n = nodes[i];
    AppendUnsigned(&out, n.parent);
    out += n.is_leaf ? " 1 " : " 0 ";
    for (std::uint8_t b : n.descriptor.bytes) {
      AppendUnsigned(&out, b);
      out += ' ';
    }
    out += ' ';
    out += bow_internal::FormatWeight(n.weight);
    out += '\n';
  }
  WriteFileAtomically(file, out);
}

}  // namespace pkslam
