// Tests of the BVH reader and writer at the file level (prior/motion/bvh.h).
#include "prior/motion/bvh.h"

#include <gtest/gtest.h>

#include <clocale>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <locale>
#include <random>
#include <string>

#include "prior/util/binary_io.h"
#include "tests/test_util.h"

namespace mf {
namespace {

using C = BvhChannel;

// A small document: a root with 6 channels, a joint with 3 in XYZ order and an
// End Site, and a joint without channels. Two frames.
const char* const kSmall =
    "HIERARCHY\n"
    "ROOT Hips\n"
    "{\n"
    "  OFFSET 1 2 3\n"
    "  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
    "  JOINT Spine\n"
    "  {\n"
    "    OFFSET 0 10.5 -0.25\n"
    "    CHANNELS 3 Xrotation Yrotation Zrotation\n"
    "    End Site\n"
    "    {\n"
    "      OFFSET 0 5 0\n"
    "    }\n"
    "  }\n"
    "  JOINT Tail\n"
    "  {\n"
    "    OFFSET 0 -1 -2e-1\n"
    "    CHANNELS 0\n"
    "  }\n"
    "}\n"
    "MOTION\n"
    "Frames: 2\n"
    "Frame Time: 0.0333333\n"
    "1 2 3 4 5 6 7 8 9\n"
    "-1.5 +2 3e2 0 0 0 -0 1E-3 .5\n";

void expect_small(const BvhDocument& doc) {
  ASSERT_EQ(doc.joints.size(), 3u);
  EXPECT_EQ(doc.joints[0].name, "Hips");
  EXPECT_EQ(doc.joints[0].parent, -1);
  EXPECT_EQ(doc.joints[0].offset, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(doc.joints[0].channels,
            (std::vector<C>{C::Xposition, C::Yposition, C::Zposition, C::Zrotation, C::Xrotation, C::Yrotation}));
  EXPECT_FALSE(doc.joints[0].has_end_site);
  EXPECT_EQ(doc.joints[1].name, "Spine");
  EXPECT_EQ(doc.joints[1].parent, 0);
  EXPECT_EQ(doc.joints[1].offset, Eigen::Vector3d(0, 10.5, -0.25));
  EXPECT_EQ(doc.joints[1].channels, (std::vector<C>{C::Xrotation, C::Yrotation, C::Zrotation}));
  EXPECT_TRUE(doc.joints[1].has_end_site);
  EXPECT_EQ(doc.joints[1].end_site, Eigen::Vector3d(0, 5, 0));
  EXPECT_EQ(doc.joints[2].name, "Tail");
  EXPECT_EQ(doc.joints[2].parent, 0);
  EXPECT_EQ(doc.joints[2].offset, Eigen::Vector3d(0, -1, -0.2));
  EXPECT_TRUE(doc.joints[2].channels.empty());
  EXPECT_EQ(doc.num_frames, 2);
  EXPECT_DOUBLE_EQ(doc.frame_time, 0.0333333);
  EXPECT_EQ(doc.num_channels(), 9);
  EXPECT_EQ(doc.channel_offset(0), 0);
  EXPECT_EQ(doc.channel_offset(1), 6);
  EXPECT_EQ(doc.channel_offset(2), 9);
  EXPECT_EQ(doc.values, (std::vector<double>{1, 2, 3, 4, 5, 6, 7, 8, 9, -1.5, 2, 300, 0, 0, 0, 0, 1e-3, 0.5}));
  EXPECT_EQ(doc.find("Spine"), 1);
  EXPECT_EQ(doc.find("Head"), -1);
}

std::string replace(std::string s, const std::string& from, const std::string& to) {
  const size_t at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) s.replace(at, from.size(), to);
  return s;
}

// Parsing `text` throws a BvhError whose message starts with "test.bvh:<line>: "
// and contains `fragment`.
void expect_error(const std::string& text, int line, const std::string& fragment) {
  try {
    parse_bvh(text, "test.bvh");
    ADD_FAILURE() << "no error; expected line " << line << ": " << fragment;
  } catch (const BvhError& e) {
    const std::string message = e.what();
    const std::string prefix = "test.bvh:" + std::to_string(line) + ": ";
    EXPECT_EQ(message.substr(0, prefix.size()), prefix) << message;
    EXPECT_NE(message.find(fragment), std::string::npos) << message;
  }
}

TEST(BvhReadTest, ParsesASmallDocument) { expect_small(parse_bvh(kSmall, "small.bvh")); }

TEST(BvhReadTest, AcceptsCrlfTabsAndByteOrderMark) {
  std::string text;
  for (char c : std::string(kSmall)) {
    if (c == '\n')
      text += "\r\n";
    else if (c == ' ')
      text += "\t";
    else
      text += c;
  }
  expect_small(parse_bvh("\xEF\xBB\xBF" + text, "crlf.bvh"));
}

TEST(BvhReadTest, AcceptsBracesNextToOtherTokensAndAnyKeywordOrder) {
  const std::string text =
      "HIERARCHY ROOT Hips{CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation OFFSET 1 2 3\n"
      "JOINT Spine{End Site{OFFSET 0 5 0}OFFSET 0 10.5 -0.25 CHANNELS 3 xrotation YROTATION Zrotation}\n"
      "JOINT Tail{OFFSET 0 -1 -0.2}}\n"
      "MOTION Frames: 2 Frame Time: 0.0333333 1 2 3 4 5 6 7 8 9 -1.5 2 300 0 0 0 0 0.001 0.5";
  expect_small(parse_bvh(text, "compact.bvh"));
}

// A C++ locale with a decimal comma, for when no such C locale is installed.
struct CommaDecimal : std::numpunct<char> {
  char do_decimal_point() const override { return ','; }
};

TEST(BvhReadTest, NumbersIgnoreTheLocale) {
  const std::locale saved_cpp = std::locale::global(std::locale(std::locale::classic(), new CommaDecimal));
  const char* old = std::setlocale(LC_NUMERIC, nullptr);
  const std::string saved_c = old ? old : "C";
  const bool c_locale_set = std::setlocale(LC_NUMERIC, "de_DE.UTF-8") || std::setlocale(LC_NUMERIC, "fr_FR.UTF-8");
  const BvhDocument doc = parse_bvh(kSmall, "small.bvh");
  const std::string written = format_bvh(doc);
  std::setlocale(LC_NUMERIC, saved_c.c_str());
  std::locale::global(saved_cpp);
  expect_small(doc);
  EXPECT_NE(written.find("OFFSET 0 10.5 -0.25"), std::string::npos);
  if (!c_locale_set) std::cout << "(no C locale with a decimal comma installed; checked the C++ locale only)\n";
}

TEST(BvhReadTest, ReadsFiles) {
  const std::string dir = test::scratch_dir("bvh_read");
  const std::string path = dir + "/small.bvh";
  std::ofstream(path) << kSmall;
  expect_small(read_bvh_file(path));
  try {
    read_bvh_file(dir + "/missing.bvh");
    ADD_FAILURE() << "no error";
  } catch (const FileError& e) {  // an InputError naming the file and the reason (prior/util/binary_io.h)
    EXPECT_EQ(std::string(e.what()), "cannot open BVH file " + dir + "/missing.bvh: No such file or directory");
  }
}

TEST(BvhErrorTest, Truncated) {
  expect_error("", 1, "empty file");
  expect_error("HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n", 4, "unexpected end of file inside joint 'Hips'");
  expect_error("HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0", 4, "unexpected end of file");
  expect_error("HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n  CHANNELS 3 Xrotation", 5, "CHANNELS 3 lists only 1");
  const std::string text = kSmall;
  // Missing last value, and missing last line.
  expect_error(text.substr(0, text.size() - 4), 25, "unexpected end of file in motion data");
  expect_error(text.substr(0, text.rfind("-1.5")), 24, "found 9");
}

TEST(BvhErrorTest, WrongChannelCounts) {
  expect_error(replace(kSmall, "CHANNELS 3 Xrotation Yrotation Zrotation", "CHANNELS 3 Xrotation Yrotation"), 9,
               "CHANNELS 3 lists only 2 channel names");
  expect_error(replace(kSmall, "CHANNELS 3", "CHANNELS 7"), 9, "between 0 and 6");
  expect_error(replace(kSmall, "CHANNELS 3", "CHANNELS 1000000"), 9, "between 0 and 6");
  expect_error(replace(kSmall, "CHANNELS 3", "CHANNELS -1"), 9, "between 0 and 6");
  expect_error(replace(kSmall, "CHANNELS 3", "CHANNELS 99999999999999999999999"), 9, "too large");
  expect_error(replace(kSmall, "CHANNELS 3", "CHANNELS three"), 9, "bad CHANNELS count");
  expect_error(replace(kSmall, "Yrotation Zrotation", "Wrotation Zrotation"), 9, "unknown channel name 'Wrotation'");
  expect_error(replace(kSmall, "Yrotation Zrotation", "Xrotation Zrotation"), 9, "listed twice");
  expect_error(replace(kSmall, "CHANNELS 0", "CHANNELS 0\n CHANNELS 0"), 19, "more than one CHANNELS");
}

TEST(BvhErrorTest, BadAndNonFiniteNumbers) {
  expect_error(replace(kSmall, "OFFSET 0 10.5", "OFFSET 0 10.5.1"), 8, "bad number '10.5.1'");
  expect_error(replace(kSmall, "OFFSET 0 10.5", "OFFSET 0 1,5"), 8, "bad number '1,5'");
  expect_error(replace(kSmall, "OFFSET 0 10.5", "OFFSET 0 nan"), 8, "non-finite value 'nan'");
  expect_error(replace(kSmall, "OFFSET 1 2 3", "OFFSET 1 -inf 3"), 4, "non-finite value '-inf'");
  expect_error(replace(kSmall, "OFFSET 1 2 3", "OFFSET 1 1e400 3"), 4, "out of range");
  expect_error(replace(kSmall, "1 2 3 4 5 6 7 8 9", "1 2 3 4 5 six 7 8 9"), 24, "bad number 'six'");
  expect_error(replace(kSmall, "1 2 3 4 5 6 7 8 9", "1 2 3 4 5 inf 7 8 9"), 24, "non-finite value 'inf'");
  expect_error(replace(kSmall, "-1.5 +2", "-1.5 NaN"), 25, "non-finite value 'NaN'");
  expect_error(replace(kSmall, "-1.5 +2", "-1.5 0x10"), 25, "bad number");
  // Underflow reads as zero.
  EXPECT_EQ(parse_bvh(replace(kSmall, "-1.5 +2", "-1.5 1e-400"), "t").values[10], 0.0);
}

TEST(BvhErrorTest, StructureErrors) {
  expect_error("HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n  CHANNELS 1 Xposition\n}\n", 6, "missing MOTION");
  expect_error("HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n  CHANNELS 1 Xposition\n}\nMOTON\n", 7, "expected MOTION");
  expect_error("HIERARCHY\nROOT A\n{\n OFFSET 0 0 0\n}\nROOT B\n{\n OFFSET 0 0 0\n}\n", 6, "more than one ROOT");
  expect_error(replace(kSmall, "HIERARCHY", "HIERARCHIE"), 1, "expected HIERARCHY");
  expect_error(replace(kSmall, "ROOT", "JOINT"), 2, "expected ROOT");
  expect_error(replace(kSmall, "JOINT Tail", "BONE Tail"), 15, "unknown keyword 'BONE'");
  expect_error(replace(kSmall, "    End Site", "    End Zone"), 10, "expected 'Site'");
  expect_error(replace(kSmall, "      OFFSET 0 5 0\n", "      OFFSET 0 5 0\n      CHANNELS 0\n"), 13, "expected '}'");
  expect_error(replace(kSmall, "JOINT Tail", "JOINT Spine"), 15, "duplicate joint name 'Spine'");
  expect_error(replace(kSmall, "    OFFSET 0 -1 -2e-1\n", ""), 18, "joint 'Tail' has no OFFSET");
  expect_error(replace(kSmall, "OFFSET 0 -1 -2e-1", "OFFSET 0 -1 -2e-1 OFFSET 0 0 0"), 17, "more than one OFFSET");
  expect_error(replace(kSmall, "    }\n  }\n  JOINT Tail", "    }\n    End Site { OFFSET 0 0 0 }\n  }\n  JOINT Tail"),
               14, "more than one End Site");
  expect_error(replace(kSmall, "JOINT Tail\n  {", "JOINT\n  {"), 16, "expected a joint name");
  expect_error(replace(kSmall, "ROOT Hips\n{", "ROOT Hips\n"), 4, "expected '{'");
  expect_error("HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n", 6, "no channels");
}

TEST(BvhErrorTest, FrameCountAndTime) {
  expect_error(replace(kSmall, "Frames: 2", "Frames: 0"), 22, "at least 1");
  expect_error(replace(kSmall, "Frames: 2", "Frames: -3"), 22, "at least 1");
  expect_error(replace(kSmall, "Frames: 2", "Frames: 1.5"), 22, "bad frame count");
  expect_error(replace(kSmall, "Frames: 2", "Frames: 1"), 25, "more motion data than Frames: 1");
  expect_error(replace(kSmall, "Frames: 2", "Frames: 3"), 25, "unexpected end of file in motion data");
  expect_error(replace(kSmall, "Frames: 2", "Frame: 2"), 22, "expected 'Frames:'");
  expect_error(replace(kSmall, "Frame Time: 0.0333333", "Frame Time: 0"), 23, "frame time must be positive");
  expect_error(replace(kSmall, "Frame Time: 0.0333333", "Frame Time: -0.1"), 23, "frame time must be positive");
  expect_error(replace(kSmall, "Frame Time: 0.0333333", "Frame Time: fast"), 23, "bad number 'fast' for frame time");
  // One value too many on the last line.
  expect_error(replace(kSmall, "1E-3 .5", "1E-3 .5 7"), 25, "extra value '7'");
}

// Counts beyond the limits are rejected before anything is allocated for them.
TEST(BvhErrorTest, HugeCounts) {
  expect_error(replace(kSmall, "Frames: 2", "Frames: 99999999999"), 22, "exceeds the limit");
  expect_error(replace(kSmall, "Frames: 2", "Frames: 99999999999999999999999"), 22, "too large");
  // 24 channels x 1e7 frames = 2.4e8 values > kBvhMaxValues.
  std::string wide = "HIERARCHY\nROOT J0\n{\nOFFSET 0 0 0\n";
  const std::string six = "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n";
  wide += six;
  for (int j = 1; j < 4; ++j) wide += "JOINT J" + std::to_string(j) + "\n{\nOFFSET 0 0 0\n" + six + "}\n";
  expect_error(wide + "}\nMOTION\nFrames: 10000000\nFrame Time: 0.1\n0 0 0\n", 23, "limit of 200000000 values");
  // Within the limits but far beyond the data: reads what is there, then fails.
  expect_error(replace(kSmall, "Frames: 2", "Frames: 1000000"), 25,
               "expected 9000000 values (1000000 frames x 9 channels), found 18");
}

std::string nested(int depth) {
  std::string text = "HIERARCHY\nROOT J0\n{\nOFFSET 0 0 0\nCHANNELS 1 Xrotation\n";
  for (int d = 1; d < depth; ++d) text += "JOINT J" + std::to_string(d) + "\n{\nOFFSET 0 1 0\n";
  for (int d = 1; d < depth; ++d) text += "}\n";
  return text + "}\nMOTION\nFrames: 1\nFrame Time: 0.1\n0\n";
}

TEST(BvhErrorTest, NestingAndJointLimits) {
  const BvhDocument ok = parse_bvh(nested(kBvhMaxDepth), "deep.bvh");
  EXPECT_EQ(ok.joints.size(), static_cast<size_t>(kBvhMaxDepth));
  EXPECT_EQ(ok.joints.back().parent, kBvhMaxDepth - 2);
  // Joint J_d is named on line 3 d + 3; J64 is at depth 65.
  expect_error(nested(kBvhMaxDepth + 1), 3 * kBvhMaxDepth + 3, "nested deeper than 64");

  std::string flat = "HIERARCHY\nROOT R\n{\nOFFSET 0 0 0\nCHANNELS 1 Xrotation\n";
  for (int j = 1; j <= kBvhMaxJoints; ++j) flat += "JOINT J" + std::to_string(j) + " { OFFSET 0 0 0 }\n";
  expect_error(flat + "}\n", 5 + kBvhMaxJoints, "more than 1024 joints");
}

// A document with random values, every channel order, position channels on a
// non-root joint, joints without channels and End Sites.
BvhDocument random_document(uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-500.0, 500.0);
  const std::vector<std::vector<C>> layouts = {
      {C::Xposition, C::Yposition, C::Zposition, C::Zrotation, C::Xrotation, C::Yrotation},
      {C::Xrotation, C::Yrotation, C::Zrotation},
      {C::Yrotation, C::Zrotation, C::Xrotation},
      {C::Zrotation, C::Yrotation, C::Xrotation, C::Xposition, C::Zposition, C::Yposition},
      {},
      {C::Yrotation, C::Xrotation, C::Zrotation},
      {C::Xrotation, C::Zrotation, C::Yrotation},
      {C::Yposition}};
  const std::vector<int> parents = {-1, 0, 1, 2, 1, 0, 5, 6};
  BvhDocument doc;
  for (size_t j = 0; j < parents.size(); ++j) {
    BvhJoint joint;
    joint.name = "joint_" + std::to_string(j);
    joint.parent = parents[j];
    joint.offset = {u(rng), u(rng) * 1e-3, u(rng) * 1e3};
    joint.channels = layouts[j];
    joint.has_end_site = j == 3 || j == 4 || j == 7;
    if (joint.has_end_site) joint.end_site = {u(rng), u(rng), 1e-7 * u(rng)};
    doc.joints.push_back(joint);
  }
  doc.num_frames = 13;
  doc.frame_time = 1.0 / 120;
  for (int n = 0; n < doc.num_frames * doc.num_channels(); ++n)
    doc.values.push_back(n % 7 == 3 ? u(rng) * 1e-5 : u(rng));
  return doc;
}

void expect_same_document(const BvhDocument& a, const BvhDocument& b, double rel) {
  auto near = [rel](double x, double y) { return std::abs(x - y) <= rel * std::max(1.0, std::abs(x)); };
  ASSERT_EQ(a.joints.size(), b.joints.size());
  for (size_t j = 0; j < a.joints.size(); ++j) {
    EXPECT_EQ(a.joints[j].name, b.joints[j].name);
    EXPECT_EQ(a.joints[j].parent, b.joints[j].parent);
    EXPECT_EQ(a.joints[j].channels, b.joints[j].channels);
    EXPECT_EQ(a.joints[j].has_end_site, b.joints[j].has_end_site);
    for (int k = 0; k < 3; ++k) {
      EXPECT_PRED2(near, a.joints[j].offset[k], b.joints[j].offset[k]);
      EXPECT_PRED2(near, a.joints[j].end_site[k], b.joints[j].end_site[k]);
    }
  }
  EXPECT_EQ(a.num_frames, b.num_frames);
  EXPECT_PRED2(near, a.frame_time, b.frame_time);
  ASSERT_EQ(a.values.size(), b.values.size());
  for (size_t i = 0; i < a.values.size(); ++i) ASSERT_PRED2(near, a.values[i], b.values[i]) << "value " << i;
}

TEST(BvhWriteTest, RoundTripsEveryChannel) {
  for (uint32_t seed : {1u, 2u, 3u}) {
    const BvhDocument doc = random_document(seed);
    ASSERT_NO_THROW(doc.validate());
    const std::string text = format_bvh(doc);
    const BvhDocument back = parse_bvh(text, "roundtrip.bvh");
    expect_same_document(doc, back, 1e-8);
    // Writing what was read gives the same text.
    EXPECT_EQ(format_bvh(back), text);
  }
}

TEST(BvhWriteTest, WritesTheExpectedText) {
  BvhDocument doc;
  BvhJoint root;
  root.name = "Hips";
  root.offset = {0, 90.5, 0};
  root.channels = {C::Yposition, C::Zrotation};
  BvhJoint leaf;
  leaf.name = "Head";
  leaf.parent = 0;
  leaf.offset = {0, 0.1, 1e-12};
  leaf.has_end_site = true;
  leaf.end_site = {0, 10, 0};
  doc.joints = {root, leaf};
  doc.num_frames = 2;
  doc.frame_time = 0.04;
  doc.values = {1.0 / 3.0, -90, 1e20, 0};
  EXPECT_EQ(format_bvh(doc),
            "HIERARCHY\n"
            "ROOT Hips\n"
            "{\n"
            "\tOFFSET 0 90.5 0\n"
            "\tCHANNELS 2 Yposition Zrotation\n"
            "\tJOINT Head\n"
            "\t{\n"
            "\t\tOFFSET 0 0.1 1e-12\n"
            "\t\tCHANNELS 0\n"
            "\t\tEnd Site\n"
            "\t\t{\n"
            "\t\t\tOFFSET 0 10 0\n"
            "\t\t}\n"
            "\t}\n"
            "}\n"
            "MOTION\n"
            "Frames: 2\n"
            "Frame Time: 0.04\n"
            "0.333333333 -90\n"
            "1e+20 0\n");
}

TEST(BvhWriteTest, RejectsDocumentsItCannotWrite) {
  const BvhDocument good = random_document(4);
  auto expect_rejected = [&](void (*edit)(BvhDocument&), const char* what) {
    BvhDocument doc = good;
    edit(doc);
    EXPECT_THROW(format_bvh(doc), InputError) << what;
  };
  expect_rejected(
      [](BvhDocument& d) {
        d.joints.clear();
        d.values.clear();
      },
      "no joints");
  expect_rejected([](BvhDocument& d) { d.values.pop_back(); }, "value count");
  expect_rejected([](BvhDocument& d) { d.values[5] = std::nan(""); }, "NaN value");
  expect_rejected([](BvhDocument& d) { d.joints[2].offset.x() = INFINITY; }, "inf offset");
  expect_rejected(
      [](BvhDocument& d) {
        d.num_frames = 0;
        d.values.clear();
      },
      "no frames");
  expect_rejected([](BvhDocument& d) { d.frame_time = 0; }, "zero frame time");
  expect_rejected([](BvhDocument& d) { d.joints[3].name = "joint_1"; }, "duplicate name");
  expect_rejected([](BvhDocument& d) { d.joints[3].name = "two words"; }, "space in name");
  expect_rejected([](BvhDocument& d) { d.joints[3].name = "a{b"; }, "brace in name");
  expect_rejected([](BvhDocument& d) { d.joints[0].parent = 2; }, "root with a parent");
  expect_rejected([](BvhDocument& d) { d.joints[3].parent = 5; }, "parent after child");
  expect_rejected([](BvhDocument& d) { d.joints[5].parent = 2; }, "not depth-first (5 under 2 after 4 under 1)");
  expect_rejected(
      [](BvhDocument& d) {
        d.joints[1].channels = {C::Xrotation, C::Xrotation, C::Zrotation};
      },
      "duplicate channel");
}

TEST(BvhWriteTest, WritesFilesAtomically) {
  const std::string dir = test::scratch_dir("bvh_write");
  const std::string path = dir + "/out.bvh";
  const BvhDocument doc = random_document(5);
  write_bvh_file(path, doc);
  expect_same_document(doc, read_bvh_file(path), 1e-8);
  // Overwrites an existing file; leaves no temporary file behind.
  write_bvh_file(path, random_document(6));
  expect_same_document(random_document(6), read_bvh_file(path), 1e-8);
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) files += entry.is_regular_file();
  EXPECT_EQ(files, 1);
  EXPECT_THROW(write_bvh_file(dir + "/no/such/dir/out.bvh", doc), std::runtime_error);
  // An invalid document is rejected before the file is touched.
  BvhDocument bad = doc;
  bad.values.pop_back();
  EXPECT_THROW(write_bvh_file(path, bad), InputError);
  expect_same_document(random_document(6), read_bvh_file(path), 1e-8);
}

TEST(BvhWriteTest, ChannelNames) {
  EXPECT_STREQ(to_string(C::Xposition), "Xposition");
  EXPECT_STREQ(to_string(C::Zrotation), "Zrotation");
}

}  // namespace
}  // namespace mf
