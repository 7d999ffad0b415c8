#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <string>

#include "core/bow/bow_test_utils.h"
#include "core/bow/vocabulary.h"
#include "core/bow/vocabulary_internal.h"
#include "core/util/error.h"
#include "tests/support/test_data.h"

namespace pkslam {
namespace {

namespace fs = std::filesystem;

// Lines as DBoW2 / ORB-SLAM write ORBvoc.txt: "k L  scoring weighting", then per node
// "parent isLeaf" + 32 bytes each followed by a space + " weight".
const char* const kOrbVocLike =
    "2 2  0 0\n"
    "0 0 252 188 188 242 169 109 85 143 187 191 164 25 222 255 72 27 129 215 237 16 58 111 219 "
    "51 219 211 85 127 192 112 134 34  0\n"
    "0 0 93 215 37 83 134 51 26 22 107 28 13 190 120 197 32 174 75 220 144 186 214 77 121 230 "
    "57 246 145 169 105 86 176 78  0\n"
    "1 1 252 188 188 242 169 109 85 143 187 191 164 25 222 255 72 27 129 215 237 16 58 111 219 "
    "51 219 211 85 127 192 112 134 98  0.00658902\n"
    "1 1 236 56 188 242 169 45 85 143 187 191 164 25 222 255 72 27 129 215 237 16 58 111 219 51 "
    "219 211 85 127 192 112 134 34  1.38629\n"
    "2 1 93 215 37 83 134 51 26 22 107 28 13 190 120 197 32 174 75 220 144 186 214 77 121 230 57 "
    "246 145 169 105 86 176 79  2.5e-05\n"
    "2 1 93 215 37 83 134 51 26 22 107 28 13 190 120 197 32 174 75 220 144 186 214 77 121 230 57 "
    "246 145 169 105 86 0 0  7.17312\n";

std::string ReadFile(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void WriteFile(const fs::path& file, const std::string& content) {
  std::ofstream(file, std::ios::binary) << content;
}

class VocabularyIo : public ::testing::Test {
 protected:
  fs::path dir_ = pkslam::testing::MakeTempDir("pkslam_vocab_io");
  void TearDown() override { fs::remove_all(dir_); }
  fs::path Write(const std::string& name, const std::string& content) {
    WriteFile(dir_ / name, content);
    return dir_ / name;
  }
};

TEST_F(VocabularyIo, LoadsOrbVocLikeText) {
  const Vocabulary v = Vocabulary::LoadText(Write("voc.txt", kOrbVocLike));
  EXPECT_EQ(v.branching(), 2);
  EXPECT_EQ(v.levels(), 2);
  EXPECT_EQ(v.scoring(), Scoring::kL1);
  EXPECT_EQ(v.weighting(), Weighting::kTfIdf);
  EXPECT_EQ(v.node_count(), 7u);
  EXPECT_EQ(v.word_count(), 4u);
  EXPECT_EQ(v.descriptor(1).bytes[0], 252);
  EXPECT_EQ(v.descriptor(1).bytes[31], 34);
  EXPECT_EQ(v.descriptor(6).bytes[30], 0);
  EXPECT_EQ(v.WordWeight(0), 0.00658902);
  EXPECT_EQ(v.WordWeight(2), 2.5e-05);
  EXPECT_EQ(v.parent(5), 2u);
  // A node descriptor quantises to its own word.
  EXPECT_EQ(v.FindWord(v.descriptor(4)), 1u);
}

TEST_F(VocabularyIo, OrbVocLikeTextRoundTripsExactlyThroughBinary) {
  const Vocabulary v = Vocabulary::LoadText(Write("in.txt", kOrbVocLike));
  v.SaveText(dir_ / "direct.txt");
  EXPECT_EQ(ReadFile(dir_ / "direct.txt"), kOrbVocLike);
  v.Save(dir_ / "voc.bin");
  Vocabulary::Load(dir_ / "voc.bin").Save(dir_ / "back.txt");
  EXPECT_EQ(ReadFile(dir_ / "back.txt"), kOrbVocLike);
}

TEST_F(VocabularyIo, GeneratedVocabularyRoundTripsExactly) {
  // Full-precision weights (not representable in 6 digits) and a DBoW2-ordered tree.
  const Vocabulary v = pkslam::testing::MakeRandomVocabulary(5, 3, 17);
  v.SaveText(dir_ / "a.txt");
  const Vocabulary from_text = Vocabulary::LoadText(dir_ / "a.txt");
  EXPECT_EQ(from_text.Nodes(), v.Nodes());  // weights bit-exact
  EXPECT_EQ(from_text.params(), v.params());
  from_text.SaveBinary(dir_ / "b.pkvoc");
  const Vocabulary from_binary = Vocabulary::LoadBinary(dir_ / "b.pkvoc");
  EXPECT_EQ(from_binary.Nodes(), v.Nodes());
  from_binary.SaveText(dir_ / "c.txt");
  EXPECT_EQ(ReadFile(dir_ / "c.txt"), ReadFile(dir_ / "a.txt"));
  v.SaveBinary(dir_ / "d.bin");
  EXPECT_EQ(ReadFile(dir_ / "d.bin"), ReadFile(dir_ / "b.pkvoc"));
}

TEST_F(VocabularyIo, AcceptsCrlfAndTabsAndTrailingBlankLines) {
  std::string text = kOrbVocLike;
  std::string crlf;
  for (char c : text) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c == ' ' ? '\t' : c);
  crlf += "\r\n\r\n";
  const Vocabulary a = Vocabulary::LoadText(Write("a.txt", kOrbVocLike));
  const Vocabulary b = Vocabulary::LoadText(Write("b.txt", crlf));
  EXPECT_EQ(a.Nodes(), b.Nodes());
}

TEST(FormatWeight, StreamStyleWhenExactElseShortest) {
  using bow_internal::FormatWeight;
  EXPECT_EQ(FormatWeight(0.0), "0");
  EXPECT_EQ(FormatWeight(0.00658902), "0.00658902");
  EXPECT_EQ(FormatWeight(1e-05), "1e-05");
  EXPECT_EQ(FormatWeight(7.5), "7.5");
  EXPECT_EQ(FormatWeight(1234567.0), "1234567");  // "%g" would print 1.23457e+06
  const double idf = std::log(3.0);
  EXPECT_EQ(std::stod(FormatWeight(idf)), idf);
}

// Expects InputError on `file` at text line `line` with `what` in the message.
void ExpectTextError(const fs::path& file, std::size_t line, const std::string& what) {
  try {
    Vocabulary::Load(file);
    ADD_FAILURE() << "no error for " << what;
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), file);
    EXPECT_EQ(e.line(), line) << e.what();
    EXPECT_THAT(e.what(), ::testing::HasSubstr(what));
  }
}

std::string ReplaceLine(std::string text, int line, const std::string& replacement) {
  std::size_t begin = 0;
  for (int i = 1; i < line; ++i) begin = text.find('\n', begin) + 1;
  const std::size_t end = text.find('\n', begin);
  return text.replace(begin, end - begin, replacement);
}

std::string Line(int line) {
  const std::string text = kOrbVocLike;
  std::size_t begin = 0;
  for (int i = 1; i < line; ++i) begin = text.find('\n', begin) + 1;
  return text.substr(begin, text.find('\n', begin) - begin);
}

TEST_F(VocabularyIo, CorruptTextNamesFileAndLine) {
  const std::string t = kOrbVocLike;
  ExpectTextError(Write("empty.txt", ""), 1, "empty vocabulary file");
  ExpectTextError(Write("h1.txt", ReplaceLine(t, 1, "10 6 0")), 1, "header");
  ExpectTextError(Write("h2.txt", ReplaceLine(t, 1, "10 x 0 0")), 1, "'x' is not an integer");
  ExpectTextError(Write("h3.txt", ReplaceLine(t, 1, "10 6  1 0")), 1, "scoring 1");
  ExpectTextError(Write("h4.txt", ReplaceLine(t, 1, "10 60  0 0")), 1, "depth L = 60");
  std::string short_line = Line(4);
  short_line = short_line.substr(0, short_line.find("  "));  // drop the weight
  ExpectTextError(Write("f.txt", ReplaceLine(t, 4, short_line)), 4, "found 34");
  ExpectTextError(Write("b.txt", ReplaceLine(t, 3, "0 0 256" + Line(3).substr(6))), 3,
                  "byte 0 '256'");
  ExpectTextError(Write("l.txt", ReplaceLine(t, 5, "1 2" + Line(5).substr(3))), 5, "leaf flag '2'");
  ExpectTextError(Write("w.txt", ReplaceLine(t, 6, Line(6).substr(0, Line(6).size() - 7) + "nan")),
                  6, "bad weight");
  ExpectTextError(Write("p.txt", ReplaceLine(t, 2, "5" + Line(2).substr(1))), 2,
                  "parent 5 is not an earlier node");
  ExpectTextError(Write("pl.txt", ReplaceLine(t, 7, "3" + Line(7).substr(1))), 7,
                  "parent 3 is a word");
  // Node 2 (line 3) loses both children (lines 6, 7), which become children of node 1.
  std::string orphan = ReplaceLine(t, 6, "1" + Line(6).substr(1));
  orphan = ReplaceLine(orphan, 7, "1" + Line(7).substr(1));
  ExpectTextError(Write("o.txt", orphan), 3, "inner node (not a leaf) without children");
  ExpectTextError(Write("blank.txt", ReplaceLine(t, 4, "\n" + Line(4))), 4,
                  "blank line inside the node list");
  // Truncated in the middle of a line.
  ExpectTextError(Write("cut.txt", t.substr(0, t.size() - 40)), 7, "expected 35 fields");
  ExpectTextError(dir_ / "missing.txt", 0, "does not exist");
}

// Expects InputError on `file` whose message names a byte offset and `what`.
void ExpectBinaryError(const fs::path& file, const std::string& what) {
  try {
    Vocabulary::LoadBinary(file);
    ADD_FAILURE() << "no error for " << what;
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), file);
    EXPECT_THAT(e.what(), ::testing::HasSubstr(file.string() + ": offset "));
    EXPECT_THAT(e.what(), ::testing::HasSubstr(what));
  }
}

TEST_F(VocabularyIo, CorruptBinaryNamesFileAndOffset) {
  Vocabulary::LoadText(Write("voc.txt", kOrbVocLike)).SaveBinary(dir_ / "voc.bin");
  const std::string good = ReadFile(dir_ / "voc.bin");
  ASSERT_EQ(good.size(), 36u + 6u * 45u + 8u);
  ExpectBinaryError(Write("magic.bin", "XX" + good.substr(2)), "offset 0: not a pkslam binary");
  ExpectBinaryError(Write("short.bin", good.substr(0, 20)), "truncated header");
  ExpectBinaryError(Write("cut.bin", good.substr(0, good.size() - 10)), "truncated");
  ExpectBinaryError(Write("long.bin", good + "x"), "1 trailing bytes");
  std::string flipped = good;
  flipped[100] = static_cast<char>(flipped[100] ^ 0x04);
  ExpectBinaryError(Write("flip.bin", flipped), "offset 306: checksum mismatch");
  std::string version = good;
  version[8] = 9;
  ExpectBinaryError(Write("version.bin", version), "offset 8: unsupported format version 9");
  ExpectBinaryError(Write("empty.bin", ""), "bad magic");
}

TEST_F(VocabularyIo, SaveByExtension) {
  const Vocabulary v = Vocabulary::LoadText(Write("voc.txt", kOrbVocLike));
  EXPECT_THROW(v.Save(dir_ / "voc.yaml"), OptionError);
  EXPECT_THROW(Vocabulary().Save(dir_ / "empty.bin"), Error);
  v.Save(dir_ / "voc.pkvoc");
  EXPECT_TRUE(IsBinaryVocabularyFile(dir_ / "voc.pkvoc"));
  EXPECT_FALSE(IsBinaryVocabularyFile(dir_ / "voc.txt"));
  EXPECT_EQ(Vocabulary::Load(dir_ / "voc.pkvoc").Nodes(), v.Nodes());
}

}  // namespace
}  // namespace pkslam
