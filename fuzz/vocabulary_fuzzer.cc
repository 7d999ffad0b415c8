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
#include "core/bow/vocabulary_internal.h"
#include "core/util/error.h"
#include "fuzz/fuzz_support.h"

namespace {

using namespace pkslam;

using bow_internal::kBinaryChecksumSize;
using bow_internal::kBinaryHeaderSize;
using bow_internal::kBinaryMagic;
using bow_internal::kBinaryNodeCountAt;
using bow_internal::kBinaryRecordSize;

void PutLE64(unsigned char* p, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<unsigned char>(v >> (8 * i));
}

// A binary input with a consistent node count, length and checksum; empty if not binary.
std::vector<unsigned char> Repaired(const std::uint8_t* data, std::size_t size) {
  if (size < kBinaryHeaderSize ||
      std::memcmp(data, kBinaryMagic.data(), kBinaryMagic.size()) != 0) {
    return {};
  }
  const std::size_t count = (size - kBinaryHeaderSize) / kBinaryRecordSize;
  const std::size_t body = kBinaryHeaderSize + count * kBinaryRecordSize;
  std::vector<unsigned char> out(data, data + body);
  PutLE64(out.data() + kBinaryNodeCountAt, count);
  out.resize(body + kBinaryChecksumSize);
  PutLE64(out.data() + body, bow_internal::BinaryChecksum(out.data(), body));
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
