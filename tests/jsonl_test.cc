#include "capi/src/jobs/jsonl.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "motionfield.hpp"

namespace motionfield::jobs {
namespace {

// Parses `text`, expects a JsonError and returns its column (0 if none was thrown).
int error_column(const std::string& text, std::string* message = nullptr) {
  try {
    parse_json(text);
  } catch (const JsonError& e) {
    if (message) *message = e.what();
    return e.column();
  }
  ADD_FAILURE() << "no error for: " << text;
  return 0;
}

TEST(JsonlTest, Scalars) {
  EXPECT_TRUE(parse_json("null").is_null());
  EXPECT_TRUE(parse_json("true").as_bool());
  EXPECT_FALSE(parse_json(" false ").as_bool());
  EXPECT_EQ(parse_json("\"abc\"").as_string(), "abc");
  EXPECT_EQ(parse_json("\"\"").as_string(), "");
}

TEST(JsonlTest, Numbers) {
  EXPECT_EQ(parse_json("0").as_number(), 0.0);
  EXPECT_EQ(parse_json("-0").as_number(), 0.0);
  EXPECT_EQ(parse_json("42").as_number(), 42.0);
  EXPECT_EQ(parse_json("-12").as_number(), -12.0);
  EXPECT_EQ(parse_json("0.25").as_number(), 0.25);
  EXPECT_EQ(parse_json("1.5e3").as_number(), 1500.0);
  EXPECT_EQ(parse_json("2E-2").as_number(), 0.02);
  EXPECT_EQ(parse_json("1e+2").as_number(), 100.0);
  EXPECT_EQ(parse_json("23.3").as_number(), 23.3);
  EXPECT_EQ(parse_json("1e-400").as_number(), 0.0);  // underflow is harmless
  EXPECT_EQ(parse_json("-9007199254740993").as_number(), -9007199254740992.0);
}

TEST(JsonlTest, StringEscapes) {
  EXPECT_EQ(parse_json(R"("a\"b\\c\/d")").as_string(), "a\"b\\c/d");
  EXPECT_EQ(parse_json(R"("\b\f\n\r\t")").as_string(), "\b\f\n\r\t");
  EXPECT_EQ(parse_json(R"("\u0041\u00e9\u20AC")").as_string(), "A\xC3\xA9\xE2\x82\xAC");   // A, e acute, euro
  EXPECT_EQ(parse_json(R"("\ud83d\ude00")").as_string(), "\xF0\x9F\x98\x80");              // surrogate pair
  EXPECT_EQ(parse_json(R"("\u0000")").as_string(), std::string(1, '\0'));
  EXPECT_EQ(parse_json("\"caf\xC3\xA9 \xF0\x9F\x98\x80\"").as_string(), "caf\xC3\xA9 \xF0\x9F\x98\x80");  // raw UTF-8
}

TEST(JsonlTest, ArraysAndObjects) {
  const JsonValue v = parse_json(R"( {"a": [1, 2, {"b": null}], "c": {}, "d": [], "e": "x"} )");
  ASSERT_TRUE(v.is_object());
  EXPECT_EQ(v.keys(), (std::vector<std::string>{"a", "c", "d", "e"}));  // input order
  const JsonValue* a = v.find("a");
  ASSERT_NE(a, nullptr);
  ASSERT_EQ(a->as_array().size(), 3u);
  EXPECT_EQ(a->as_array()[1].as_number(), 2.0);
  EXPECT_TRUE(a->as_array()[2].find("b")->is_null());
  EXPECT_TRUE(v.find("c")->is_object());
  EXPECT_TRUE(v.find("d")->as_array().empty());
  EXPECT_EQ(v.find("missing"), nullptr);
  EXPECT_EQ(a->find("b"), nullptr);  // not an object
  EXPECT_EQ(v.dump(), R"({"a":[1,2,{"b":null}],"c":{},"d":[],"e":"x"})");
}

TEST(JsonlTest, DumpEscapesAndRoundTrips) {
  const std::string text = R"(["q\"\\\n\u0001",true,false,null,-0.5,1e+300])";
  const JsonValue v = parse_json(text);
  EXPECT_EQ(v.dump(), R"(["q\"\\\n\u0001",true,false,null,-0.5,1e+300])");
  EXPECT_EQ(parse_json(v.dump()).dump(), v.dump());
}

// The sign of zero survives a dump and a parse: -0.0 dumps as "-0.0" (the
// text "-0" is the integer 0 to the parser), so a dump reads back to the same
// value and dumps to the same text.
TEST(JsonlTest, NegativeZeroRoundTrips) {
  const JsonValue v = parse_json("[-0.0, -0e5, 0.0, -0]");
  EXPECT_EQ(v.dump(), "[-0.0,-0.0,0,0]");
  const JsonValue back = parse_json(v.dump());
  EXPECT_TRUE(std::signbit(back.as_array()[0].as_number()));
  EXPECT_FALSE(std::signbit(back.as_array()[2].as_number()));
  EXPECT_EQ(back.dump(), v.dump());
  EXPECT_EQ(JsonValue::number(-0.0).dump(), "-0.0");
  EXPECT_EQ(parse_json(JsonValue::number(-0.0).dump()).dump(), "-0.0");
}

TEST(JsonlTest, WrongTypeAccessThrowsLogicError) {
  EXPECT_THROW(parse_json("1").as_string(), std::logic_error);
  EXPECT_THROW(parse_json("[]").keys(), std::logic_error);
}

TEST(JsonlTest, ErrorsNameTheColumn) {
  std::string m;
  EXPECT_EQ(error_column(R"({"a": 1,})", &m), 9);  // trailing comma in an object
  EXPECT_NE(m.find("column 9: "), std::string::npos) << m;
  EXPECT_NE(m.find("trailing comma"), std::string::npos) << m;
  EXPECT_EQ(error_column("[1, 2,]", &m), 7);
  EXPECT_NE(m.find("trailing comma"), std::string::npos) << m;
  EXPECT_EQ(error_column("{} x"), 4);           // garbage after the value
  EXPECT_EQ(error_column("[1 2]"), 4);          // missing comma
  EXPECT_EQ(error_column(R"({"a" 1})"), 6);     // missing colon
  EXPECT_EQ(error_column("{a: 1}"), 2);         // unquoted key
  EXPECT_EQ(error_column("['a']"), 2);          // single quotes
  EXPECT_EQ(error_column(""), 1);               // empty input
  EXPECT_EQ(error_column("   "), 4);
  EXPECT_EQ(error_column("[1, // c\n 2]"), 5);  // comments
  // Columns count characters, not bytes: the two-byte e acute is one column.
  EXPECT_EQ(error_column("[\"\xC3\xA9\",]"), 6);
}

TEST(JsonlTest, RejectsBadNumbers) {
  EXPECT_EQ(error_column("01"), 2);
  EXPECT_EQ(error_column("-"), 2);
  EXPECT_EQ(error_column("+1"), 1);
  EXPECT_EQ(error_column("1."), 3);
  EXPECT_EQ(error_column(".5"), 1);
  EXPECT_EQ(error_column("1e"), 3);
  EXPECT_EQ(error_column("1e+"), 4);
  EXPECT_EQ(error_column("0x10"), 2);
  EXPECT_EQ(error_column("NaN"), 1);
  EXPECT_EQ(error_column("-Infinity"), 2);
  std::string m;
  EXPECT_EQ(error_column("[1e400]", &m), 2);
  EXPECT_NE(m.find("out of range"), std::string::npos) << m;
  EXPECT_EQ(error_column("-1234567890123456789012345678901234567890e300"), 1);
}

// Syntax errors name the column where nlohmann's lexer detected them (for a
// truncated token, one past its end) and quote what it last read.
TEST(JsonlTest, RejectsBadLiteralsAndStrings) {
  std::string m;
  EXPECT_EQ(error_column("tru", &m), 4);
  EXPECT_NE(m.find("last read: 'tru'"), std::string::npos) << m;
  EXPECT_EQ(error_column("nulll"), 5);
  EXPECT_EQ(error_column("True"), 1);
  EXPECT_EQ(error_column("\"abc"), 5);              // unterminated
  EXPECT_EQ(error_column("\"a\tb\""), 3);           // raw control character
  EXPECT_EQ(error_column(R"("a\xb")"), 4);          // unknown escape
  EXPECT_EQ(error_column(R"("\u12G4")"), 6);        // bad hex digit
  EXPECT_EQ(error_column(R"("\u12")"), 6);          // truncated
  EXPECT_EQ(error_column(R"("\ude00")"), 7);        // lone low surrogate
  EXPECT_EQ(error_column(R"("\ud83dx")"), 8);       // high surrogate alone
  EXPECT_EQ(error_column(R"("\ud83d\u0041")"), 13); // high surrogate + non-low
  EXPECT_EQ(error_column("\"\xFF\""), 2);           // invalid UTF-8
  EXPECT_EQ(error_column("\"\xC3\""), 3);           // truncated UTF-8
  EXPECT_EQ(error_column("\"\xC0\xAF\""), 2);       // overlong encoding
  EXPECT_EQ(error_column("\"\xED\xA0\x80\""), 3);   // UTF-8-encoded surrogate
}

TEST(JsonlTest, RejectsDuplicateKeysAndDeepNesting) {
  std::string m;
  EXPECT_EQ(error_column(R"({"a": 1, "a": 2})", &m), 10);
  EXPECT_NE(m.find("duplicate key \"a\""), std::string::npos) << m;
  EXPECT_EQ(error_column(R"({"x": {"a\"": 1, "a\"": 2}})", &m), 18);  // escaped quotes in the key
  EXPECT_NE(m.find("duplicate key \"a\"\""), std::string::npos) << m;
  EXPECT_NO_THROW(parse_json(R"({"a": {"a": 1}, "b": {"a": 2}, "c": [{"a": 3}, {"a": 4}]})"));  // other objects
  const std::string ok = std::string(kJsonMaxDepth, '[') + std::string(kJsonMaxDepth, ']');
  EXPECT_NO_THROW(parse_json(ok));
  const std::string deep = std::string(kJsonMaxDepth + 1, '[') + std::string(kJsonMaxDepth + 1, ']');
  EXPECT_EQ(error_column(deep, &m), kJsonMaxDepth + 1);
  EXPECT_NE(m.find("nesting"), std::string::npos) << m;
  EXPECT_THROW(parse_json(std::string(100000, '[')), JsonError);  // no stack overflow
}

// ------------------------------------------------------------ batch jobs

BatchJob job(const std::string& line) { return batch_job_from_json(parse_json(line)); }

std::string job_error(const std::string& line) {
  try {
    job(line);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no error for: " << line;
  return "";
}

TEST(JsonlTest, InbetweenJobIgnoresKeysItDoesNotNeed) {
  const BatchJob j = job(R"({"id": "walk-3", "task": "inbetween", "in": "a.bvh", "out": "b/c.bvh",)"
                         R"( "keyframes": [0, 15, 30], "frames": 31, "fps": "thirty", "gap": "n/a", "note": {"x": [1]}})");
  EXPECT_EQ(j.task, "inbetween");
  EXPECT_EQ(j.in, "a.bvh");
  EXPECT_EQ(j.out, "b/c.bvh");
  EXPECT_EQ(j.id, "walk-3");
  EXPECT_TRUE(j.method.empty());
  EXPECT_TRUE(j.has_keyframes);
  EXPECT_EQ(j.keyframes, (std::vector<int>{0, 15, 30}));
  EXPECT_FALSE(j.has_gap);
}

TEST(JsonlTest, FillJobUsesGapUnlessKeyframesAreGiven) {
  BatchJob j = job(R"({"task": "fill", "in": "a.bvh", "out": "b.bvh", "gap": [10, 20], "method": "zerovel", "id": 7})");
  EXPECT_TRUE(j.has_gap);
  EXPECT_FALSE(j.has_keyframes);
  EXPECT_EQ(j.gap_begin, 10);
  EXPECT_EQ(j.gap_end, 20);
  EXPECT_EQ(j.method, "zerovel");
  EXPECT_EQ(j.id, "7");
  // keyframes is authoritative: the gap is then not even read.
  j = job(R"({"task": "fill", "in": "a.bvh", "out": "b.bvh", "gap": "whatever", "keyframes": [0, 5, 9]})");
  EXPECT_TRUE(j.has_keyframes);
  EXPECT_FALSE(j.has_gap);
  EXPECT_EQ(j.keyframes, (std::vector<int>{0, 5, 9}));
}

TEST(JsonlTest, ResampleJob) {
  const BatchJob j = job(R"({"task": "resample", "in": "a.bvh", "out": "b.bvh", "fps": 23.5, "keyframes": "x"})");
  EXPECT_EQ(j.fps, 23.5);
  EXPECT_FALSE(j.has_keyframes);
}

TEST(JsonlTest, RenavJobTakesAPathOrAPolyline) {
  const BatchJob a = job(R"({"task": "renav", "in": "a.bvh", "out": "b.bvh", "path": "p.csv", "method": "nemf"})");
  EXPECT_EQ(a.path_file, "p.csv");
  EXPECT_FALSE(a.polyline);
  EXPECT_EQ(a.fps, 0.0);
  EXPECT_EQ(a.method, "nemf");
  const BatchJob b = job(R"({"task": "renav", "in": "a.bvh", "out": "b.bvh", "polyline": "v.csv", "frames": 90, "fps": 60})");
  EXPECT_EQ(b.path_file, "v.csv");
  EXPECT_TRUE(b.polyline);
  EXPECT_EQ(b.frames, 90);
  EXPECT_EQ(b.fps, 60.0);
  auto has = [](const std::string& m, const std::string& part) { return m.find(part) != std::string::npos; };
  EXPECT_TRUE(has(job_error(R"({"task": "renav", "in": "a", "out": "b"})"), "exactly one of \"path\" and \"polyline\""));
  EXPECT_TRUE(has(job_error(R"({"task": "renav", "in": "a", "out": "b", "path": "p", "polyline": "q"})"),
                  "exactly one of"));
  EXPECT_TRUE(has(job_error(R"({"task": "renav", "in": "a", "out": "b", "path": 3})"), "\"path\" must be a string"));
  EXPECT_TRUE(has(job_error(R"({"task": "renav", "in": "a", "out": "b", "path": "p", "frames": 10})"),
                  "\"frames\" goes with \"polyline\""));
  EXPECT_TRUE(has(job_error(R"({"task": "renav", "in": "a", "out": "b", "polyline": "p", "frames": 1.5})"), "integer"));
  EXPECT_TRUE(has(job_error(R"({"task": "renav", "in": "a", "out": "b", "path": "p", "fps": 0})"), "positive"));
  EXPECT_TRUE(has(job_error(R"({"task": "renav", "in": "a", "out": "b", "path": "p", "fps": "30"})"), "a number"));
}

TEST(JsonlTest, TransitionJob) {
  const BatchJob d = job(R"({"task": "transition", "in": "a.bvh", "to": "b.bvh", "out": "t.bvh"})");
  EXPECT_EQ(d.to, "b.bvh");
  EXPECT_EQ(d.frames, 0);
  EXPECT_EQ(d.from_frame, -1);
  EXPECT_EQ(d.to_frame, 0);
  EXPECT_FALSE(d.place_keep);
  EXPECT_FALSE(d.only_transition);
  EXPECT_FALSE(d.constrained());
  const BatchJob j = job(R"({"task": "transition", "in": "a.bvh", "to": "b.bvh", "out": "t.bvh", "frames": 20,
                             "from_frame": -3, "to_frame": 4, "place": "keep", "only_transition": true,
                             "constraints": {"targets": []}, "alternatives": 2})");
  EXPECT_EQ(j.frames, 20);
  EXPECT_EQ(j.from_frame, -3);
  EXPECT_EQ(j.to_frame, 4);
  EXPECT_TRUE(j.place_keep);
  EXPECT_TRUE(j.only_transition);
  EXPECT_EQ(j.alternatives, 2);
  EXPECT_TRUE(j.constrained());
  auto has = [](const std::string& m, const std::string& part) { return m.find(part) != std::string::npos; };
  const std::string base = R"({"task": "transition", "in": "a", "out": "b", )";
  EXPECT_TRUE(has(job_error(R"({"task": "transition", "in": "a", "out": "b"})"), "missing key \"to\""));
  EXPECT_TRUE(has(job_error(base + R"("to": 3})"), "\"to\" must be a string"));
  EXPECT_TRUE(has(job_error(base + R"("to": "c", "place": "here"})"), "\"place\" must be \"auto\" or \"keep\""));
  EXPECT_TRUE(has(job_error(base + R"("to": "c", "frames": 1.5})"), "\"frames\" must be an integer"));
  EXPECT_TRUE(has(job_error(base + R"("to": "c", "from_frame": "x"})"), "\"from_frame\" must be an integer"));
  EXPECT_TRUE(has(job_error(base + R"("to": "c", "only_transition": 1})"), "\"only_transition\" must be true or false"));
}

TEST(JsonlTest, CompletionJobsTakeTheFallbackSwitch) {
  EXPECT_TRUE(job(R"({"task": "fill", "in": "a", "out": "b", "gap": [1, 5]})").fallback);
  EXPECT_FALSE(job(R"({"task": "fill", "in": "a", "out": "b", "gap": [1, 5], "fallback": false})").fallback);
  EXPECT_FALSE(job(R"({"task": "inbetween", "in": "a", "out": "b", "keyframes": [0, 9], "fallback": false})").fallback);
  EXPECT_FALSE(job(R"({"task": "transition", "in": "a", "to": "c", "out": "b", "fallback": false})").fallback);
  EXPECT_TRUE(job(R"({"task": "resample", "in": "a", "out": "b", "fps": 60, "fallback": 3})").fallback);  // not read
  const std::string m = job_error(R"({"task": "fill", "in": "a", "out": "b", "gap": [1, 5], "fallback": "no"})");
  EXPECT_NE(m.find("\"fallback\" must be true or false"), std::string::npos) << m;
}

TEST(JsonlTest, EveryJobTakesARigMapAndUnits) {
  const BatchJob a = job(R"({"task": "inbetween", "in": "a.bvh", "out": "b.bvh", "keyframes": [0, 9], "rig_map": "m.json", "units": "in"})");
  EXPECT_EQ(a.rig_map, "m.json");
  EXPECT_EQ(a.units, "in");
  const BatchJob b = job(R"({"task": "renav", "in": "a.bvh", "out": "b.bvh", "path": "p.csv", "units": 0.01})");
  EXPECT_EQ(std::stod(b.units), 0.01);
  EXPECT_EQ(b.rig_map, "");
  auto has = [](const std::string& m, const std::string& part) { return m.find(part) != std::string::npos; };
  EXPECT_TRUE(has(job_error(R"({"task": "fill", "in": "a", "out": "b", "gap": [1, 2], "rig_map": 3})"),
                  "\"rig_map\" must be a string"));
  EXPECT_TRUE(has(job_error(R"({"task": "fill", "in": "a", "out": "b", "gap": [1, 2], "units": -1})"), "positive"));
  EXPECT_TRUE(has(job_error(R"({"task": "fill", "in": "a", "out": "b", "gap": [1, 2], "units": [1]})"),
                  "a unit name or a number"));
}

// Issue 18, item 4: a NUL would silently cut a file name ("a.bvh\u0000.evil" would read a.bvh).
TEST(JsonlTest, NulInAStringIsRefused) {
  EXPECT_EQ(job_error(R"({"task": "inbetween", "in": "a.bvh\u0000.evil", "out": "b", "keyframes": [0, 1]})"),
            "\"in\" contains a NUL character (\\u0000), which no file name or value can hold");
  EXPECT_NE(job_error(R"({"task": "inbetween", "in": "a", "out": "b\u0000", "keyframes": [0, 1]})").find("\"out\" contains a NUL"),
            std::string::npos);
  EXPECT_NE(job_error(R"({"task": "renav", "in": "a", "out": "b", "path": "p\u0000.csv"})").find("\"path\" contains a NUL"),
            std::string::npos);
  EXPECT_NE(job_error(R"({"task": "fill", "in": "a", "out": "b", "gap": [1, 2], "rig_map": "m\u0000"})")
                .find("\"rig_map\" contains a NUL"),
            std::string::npos);
}

TEST(JsonlTest, BadJobsNameTheProblem) {
  auto has = [](const std::string& m, const std::string& part) { return m.find(part) != std::string::npos; };
  EXPECT_TRUE(has(job_error("[1, 2]"), "JSON object"));
  EXPECT_TRUE(has(job_error(R"({"in": "a", "out": "b"})"), "missing key \"task\""));
  EXPECT_TRUE(has(job_error(R"({"task": "dance", "in": "a", "out": "b"})"), "unknown task \"dance\""));
  EXPECT_TRUE(has(job_error(R"({"task": 3, "in": "a", "out": "b"})"), "\"task\" must be a string"));
  EXPECT_TRUE(has(job_error(R"({"task": "fill", "out": "b", "gap": [1, 2]})"), "missing key \"in\""));
  EXPECT_TRUE(has(job_error(R"({"task": "fill", "in": "", "out": "b", "gap": [1, 2]})"), "\"in\" must not be empty"));
  EXPECT_TRUE(has(job_error(R"({"task": "fill", "in": "a", "out": 5, "gap": [1, 2]})"), "\"out\" must be a string"));
  EXPECT_TRUE(has(job_error(R"({"task": "inbetween", "in": "a", "out": "b"})"), "missing key \"keyframes\""));
  EXPECT_TRUE(has(job_error(R"({"task": "inbetween", "in": "a", "out": "b", "keyframes": "0,5"})"), "array of integers"));
  EXPECT_TRUE(has(job_error(R"({"task": "inbetween", "in": "a", "out": "b", "keyframes": [0, 1.5]})"),
                  "\"keyframes\" item 1 must be an integer, not 1.5"));
  EXPECT_TRUE(has(job_error(R"({"task": "inbetween", "in": "a", "out": "b", "keyframes": [0, 1e10]})"), "integer"));
  EXPECT_TRUE(has(job_error(R"({"task": "fill", "in": "a", "out": "b"})"), "missing key \"gap\""));
  EXPECT_TRUE(has(job_error(R"({"task": "fill", "in": "a", "out": "b", "gap": [1, 2, 3]})"), "two integers"));
  EXPECT_TRUE(has(job_error(R"({"task": "fill", "in": "a", "out": "b", "gap": [1, "2"]})"), "\"gap\" item 1"));
  EXPECT_TRUE(has(job_error(R"({"task": "resample", "in": "a", "out": "b"})"), "missing key \"fps\""));
  EXPECT_TRUE(has(job_error(R"({"task": "resample", "in": "a", "out": "b", "fps": "60"})"), "\"fps\" must be a number"));
  EXPECT_TRUE(has(job_error(R"({"task": "resample", "in": "a", "out": "b", "fps": 60, "method": 1})"),
                  "\"method\" must be a string"));
  EXPECT_TRUE(has(job_error(R"({"task": "resample", "in": "a", "out": "b", "fps": 60, "max_iterations": -1})"),
                  "\"max_iterations\" must be between 0 and 100000, not -1"));
  EXPECT_TRUE(has(job_error(R"({"task": "resample", "in": "a", "out": "b", "fps": 60, "max_iterations": 2.5})"),
                  "\"max_iterations\" must be an integer, not 2.5"));
  EXPECT_EQ(batch_job_from_json(parse_json(R"({"task": "renav", "in": "a", "out": "b", "path": "p.csv",
                                               "max_iterations": 7})"))
                .max_iterations,
            7);
}

}  // namespace
}  // namespace motionfield::jobs
