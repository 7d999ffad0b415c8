// Fuzz target: vocabulary files (core/bow/vocabulary.h Vocabulary::Load: pkslam's binary
// format, recognised by its magic, else DBoW2 text). The input is the file. Bad input must end
// in InputError; anything else is a finding. Random bytes rarely carry the binary format's
// node count and checksum, so a binary input is also loaded once more "repaired": node count
// from the size, trailing bytes cut, checksum recomputed (the tree checks behind them are what
// matter). A loaded vocabulary must quantise descriptors and round-trip through both formats
// to the same nodes (the header promises it).
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "core/bow/vocabulary.h"
#include "core/util/error.h"
#include "fuzz/fuzz_support.h"

namespace {

using namespace pkslam;

constexpr char kMagic[] = "PKVOCAB\n";
constexpr std::size_t kHeaderSize = 36;
constexpr std::size_t kRecordSize = 45;
constexpr std::size_t kChecksumSize = 8;

std::uint64_t GetLE64(const unsigned char* p) {
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v |= std::uint64_t{p[i]} << (8 * i);
  return v;
}

void PutLE64(unsigned char* p, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<unsigned char>(v >> (8 * i));
}

// The binary format's checksum (a copy of core/bow/vocabulary_binary_io.cc: Checksum).
std::uint64_t Checksum(const unsigned char* data, std::size_t size) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  constexpr std::uint64_t kPrime = 0x100000001b3ULL;
  std::size_t i = 0;
  for (; i + 8 <= size; i += 8) {
    h ^= GetLE64(data + i);
    h *= kPrime;
    h ^= h >> 29;
  }
  for (; i < size; ++i) {
    h ^= data[i];
    h *= kPrime;
  }
  return h;
}

// A binary input with a consistent node count, length and checksum; empty if not binary.
std::vector<unsigned char> Repaired(const std::uint8_t* data, std::size_t size) {
  if (size < kHeaderSize || std::memcmp(data, kMagic, 8) != 0) return {};
  const std::size_t count = (size - kHeaderSize) / kRecordSize;
  const std::size_t body = kHeaderSize + count * kRecordSize;
  std::vector<unsigned char> out(data, data + body);
  PutLE64(out.data() + 28, count);
  out.resize(body + kChecksumSize);
  PutLE64(out.data() + body, Checksum(out.data(), body));
  return out;
}

void Exercise(const Vocabulary& v) {
  const std::vector<VocabularyNode> nodes = v.Nodes();
  if (nodes.size() != v.node_count() || v.word_count() == 0) {
    fuzz::Finding("a loaded vocabulary has no words or inconsistent node counts");
  }
  v.depth();
  v.NodesPerLevel();
  v.WordsPerLevel();
  // Descriptors of a few nodes (words and inner nodes) and two extremes.
  std::vector<Descriptor> descriptors;
  for (std::size_t i = 0; i < nodes.size() && descriptors.size() < 8; i += 1 + nodes.size() / 8) {
    descriptors.push_back(nodes[i].descriptor);
  }
  descriptors.emplace_back();
  Descriptor ones;
  ones.bytes.fill(0xFF);
  descriptors.push_back(ones);
  for (const Descriptor& d : descriptors) {
    const WordId word = v.FindWord(d);
    if (word >= v.word_count()) fuzz::Finding(fmt::format("FindWord gave word {}", word));
  }
  BowVector bow;
  FeatureVector features;
  v.Transform(descriptors, &bow, &features);
  v.Transform(descriptors, &bow, &features, v.levels());

  for (const char* name : {"back.bin", "back.txt"}) {
    const auto file = fuzz::ScratchDir() / name;
    v.Save(file);
    try {
      const Vocabulary back = Vocabulary::Load(file);
      if (back.params() != v.params() || back.Nodes() != nodes) {
        fuzz::Finding(fmt::format("{} round trip changed the vocabulary", name));
      }
    } catch (const InputError& e) {
      fuzz::Finding(fmt::format("a saved vocabulary ({}) does not load: {}", name, e.what()));
    }
  }
}

void LoadAndExercise(const std::uint8_t* data, std::size_t size) {
  const auto file = fuzz::WriteScratchFile("vocabulary", data, size);
  std::optional<Vocabulary> v;
  try {
    v.emplace(Vocabulary::Load(file));
  } catch (const InputError& e) {
    fuzz::Rejected(e);
    return;
  }
  Exercise(*v);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  pkslam::fuzz::QuietLogging();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  LoadAndExercise(data, size);
  const std::vector<unsigned char> repaired = Repaired(data, size);
  if (!repaired.empty() && (repaired.size() != size || std::memcmp(repaired.data(), data, size))) {
    LoadAndExercise(repaired.data(), repaired.size());
  }
  return 0;
}
