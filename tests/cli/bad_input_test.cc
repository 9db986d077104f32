// The bad-input corpus: well over 100 bad inputs across every subcommand (configs, trajectories,
// annotations, RGB-D folders, meshes, study CSVs, outputs, flags), run through the mmh binary as
// a user would. Each must exit with code 2 (bad input) within the time limit, print a short
// message naming the file and line or key, the value and what was expected, and leave nothing
// under --out. The test fails on a crash (a signal), a hang, exit 0 or 1, a message that echoes a
// huge input, or any file left behind.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "core/annotation.h"
#include "core/image_io.h"
#include "core/tum_io.h"
#include "tests/test_util.h"

namespace mmh {
namespace {

namespace fs = std::filesystem;
using test_util::ReadBytes;
using test_util::TempDir;
using test_util::WriteText;

// A case: files written into its own folder D, then `mmh ARGS`. In ARGS and in file contents
// {D} is the case folder, {OUT} the output path (D/out unless `out` says otherwise), {T0}, {T1},
// {A0}, {A1} valid takes and annotations, {STUDY} a valid study folder, {RGBD} a rendered RGB-D
// folder (its model.ply inside), {SRC} the source tree.
struct BadInput {
  std::string name;
  std::string args;
  std::vector<std::string> expect;           // substrings of the message (file, key, value, ...)
  std::map<std::string, std::string> files;  // name in D -> contents
  std::function<void(const fs::path& d)> setup = nullptr;  // more preparation
  std::string out = "{D}/out";
};

constexpr double kRate = 30.0;

std::string TakeLines(int frames, double phase) {
  std::ostringstream s;
  for (int i = 0; i < frames; ++i) {
    const double a = 2 * M_PI * i / frames + phase;
    s << FormatNumber(i / kRate) << ' ' << FormatNumber(0.3 * std::cos(a)) << ' '
      << FormatNumber(0.3 * std::sin(a)) << " 0.05 0 0 " << FormatNumber(std::sin(a / 2)) << ' '
      << FormatNumber(std::cos(a / 2)) << '\n';
  }
  return s.str();
}

std::string AnnotationLines(int frames, double scale = 1.0, double shift = 0.0) {
  std::ostringstream s;
  s << "timestamp,value\n";
  for (int i = 0; i < frames; ++i) {
    s << FormatNumber(i / kRate * scale + shift) << ',' << FormatNumber(4 * std::sin(0.1 * i))
      << '\n';
  }
  return s.str();
}

std::string Replace(std::string text, const std::map<std::string, std::string>& values) {
  for (const auto& [key, value] : values) {
    for (std::size_t pos = text.find(key); pos != std::string::npos;
         pos = text.find(key, pos + value.size())) {
      text.replace(pos, key.size(), value);
    }
  }
  return text;
}

struct Outcome {
  int exit_code = -1;  // 124: timed out; 128 + n: killed by signal n
  std::string output;
};

Outcome RunCommand(const std::string& args) {
  // A hang is a failure: 120 s is far beyond any bad input's refusal (they take milliseconds).
  // From the source tree: the shipped configs name their stories relative to it.
  const std::string command = "cd " + std::string(MMH_SOURCE_DIR) + " && timeout -k 5 120 " +
                              std::string(MMH_BINARY) + " " + args + " 2>&1 </dev/null";
  Outcome o;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) {
    ADD_FAILURE() << "popen failed for a command of " << command.size() << " bytes";
    return o;
  }
  char buffer[4096];
  std::size_t n;
  while ((n = fread(buffer, 1, sizeof(buffer), pipe)) > 0) o.output.append(buffer, n);
  const int status = pclose(pipe);
  o.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return o;
}

// Shared valid inputs, made once.
struct Fixture {
  TempDir dir;
  fs::path rgbd;
  Fixture() {
    WriteText(dir / "t0.tum", TakeLines(200, 0.0));
    WriteText(dir / "t1.tum", TakeLines(220, 0.3));
    WriteText(dir / "a0.csv", AnnotationLines(200));
    WriteText(dir / "a1.csv", AnnotationLines(220));
    fs::copy(fs::path(MMH_SOURCE_DIR) / "examples" / "study_data", dir / "study");
    rgbd = dir / "rgbd";
    const Outcome r = RunCommand("render --quiet --set render.frames=3 --out " + rgbd.string());
    EXPECT_EQ(r.exit_code, 0) << r.output;
  }
  std::map<std::string, std::string> Values(const fs::path& d) const {
    return {{"{D}", d.string()},
            {"{T0}", (dir / "t0.tum").string()},
            {"{T1}", (dir / "t1.tum").string()},
            {"{A0}", (dir / "a0.csv").string()},
            {"{A1}", (dir / "a1.csv").string()},
            {"{STUDY}", (dir / "study").string()},
            {"{RGBD}", rgbd.string()},
            {"{SRC}", MMH_SOURCE_DIR}};
  }
};

// compose with the second take or annotation replaced.
std::string ComposeTake(const std::string& take) {
  return "compose --takes {T0} " + take + " --annotations {A0} {A1} --out {OUT}";
}
std::string ComposeAnnotation(const std::string& annotation) {
  return "compose --takes {T0} {T1} --annotations {A0} " + annotation + " --out {OUT}";
}
std::string ComposeWith(const std::string& extra) {
  return "compose --takes {T0} {T1} --annotations {A0} {A1} --out {OUT} " + extra;
}

// A copy of the rendered folder, for damaging.
std::function<void(const fs::path&)> CopyRgbd(const fs::path& rgbd,
                                              std::function<void(const fs::path&)> damage) {
  return [rgbd, damage](const fs::path& d) {
    fs::copy(rgbd, d / "in", fs::copy_options::recursive);
    damage(d / "in");
  };
}

std::vector<fs::path> DepthImages(const fs::path& folder) {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(folder / "depth")) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<BadInput> Corpus(const Fixture& fx) {
  const std::string take_line_2 = "0.0333 0.3 0 0.05 0 0 0 1\n";
  const std::string utf16_take = std::string(
      "\xFF\xFE"
      "0\0 \0"
      "0\0",
      8);
  // An ELF header's first 12 bytes, zeros included (sizeof counts the literal's terminator).
  static constexpr char kElfStart[] =
      "\x7F"
      "ELF\x02\x01\x01\0\0\0\0\0";
  const std::string garbage = std::string(kElfStart, sizeof(kElfStart) - 1) + "\xDE\xAD";
  std::vector<BadInput> c = {
      // ---- Trajectories (TUM) -----------------------------------------------------------------
      {"tum: missing column",
       ComposeTake("{D}/bad.tum"),
       {"bad.tum:1", "7 fields", "8 fields"},
       {{"bad.tum", "0 0 0 0 0 0 1\n"}}},
      {"tum: extra column",
       ComposeTake("{D}/bad.tum"),
       {"bad.tum:2", "9 fields"},
       {{"bad.tum", "0 0 0 0 0 0 0 1\n0.1 0 0 0 0 0 0 1 7\n"}}},
      {"tum: NaN",
       ComposeTake("{D}/bad.tum"),
       {"bad.tum:2, field tx", "'nan'", "finite"},
       {{"bad.tum", "0 0 0 0 0 0 0 1\n0.1 nan 0 0 0 0 0 1\n"}}},
      {"tum: Inf",
       ComposeTake("{D}/bad.tum"),
       {"bad.tum:2, field ty", "'inf'", "finite"},
       {{"bad.tum", "0 0 0 0 0 0 0 1\n0.1 0 inf 0 0 0 0 1\n"}}},
      {"tum: NaN timestamp",
       ComposeTake("{D}/bad.tum"),
       {"bad.tum:1, field timestamp", "'NaN'"},
       {{"bad.tum", "NaN 0 0 0 0 0 0 1\n"}}},
      {"tum: text",
       ComposeTake("{D}/bad.tum"),
       {"bad.tum:1, field qw", "'one'", "a finite number"},
       {{"bad.tum", "0 0 0 0 0 0 0 one\n"}}},
      {"tum: hex number",
       ComposeTake("{D}/bad.tum"),
       {"bad.tum:1, field timestamp", "'0x10'"},
       {{"bad.tum", "0x10 0 0 0 0 0 0 1\n"}}},
      {"tum: zero quaternion",
       ComposeTake("{D}/bad.tum"),
       {"bad.tum:2", "a zero quaternion"},
       {{"bad.tum", "0 0 0 0 0 0 0 1\n0.1 0 0 0 0 0 0 0\n"}}},
      {"tum: non-unit quaternion",
       ComposeTake("{D}/bad.tum"),
       {"bad.tum:1, quaternion norm", "got 2", "a unit quaternion"},
       {{"bad.tum", "0 0 0 0 0 0 0 2\n"}}},
      {"tum: unsorted timestamps",
       ComposeTake("{D}/bad.tum"),
       {"bad.tum:3, timestamp", "got 0.05", "greater than the previous timestamp 0.1"},
       {{"bad.tum", "0 0 0 0 0 0 0 1\n0.1 0 0 0 0 0 0 1\n0.05 0 0 0 0 0 0 1\n"}}},
      {"tum: duplicate timestamps",
       ComposeTake("{D}/bad.tum"),
       {"bad.tum:2, timestamp", "got 0", "greater than the previous timestamp 0"},
       {{"bad.tum", "0 0 0 0 0 0 0 1\n0 0 0 0 0 0 0 1\n"}}},
      {"tum: CRLF with a bad line 3",
       ComposeTake("{D}/bad.tum"),
       {"bad.tum:3, field tz", "'x'"},
       {{"bad.tum", "0 0 0 0 0 0 0 1\r\n0.1 0 0 0 0 0 0 1\r\n0.2 0 0 x 0 0 0 1\r\n"}}},
      {"tum: BOM, bad line 2",
       ComposeTake("{D}/bad.tum"),
       {"bad.tum:2", "7 fields"},
       {{"bad.tum",
         "\xEF\xBB\xBF"
         "0 0 0 0 0 0 0 1\n0.1 0 0 0 0 0 1\n"}}},
      {"tum: a single line",
       "compose --takes {T0} {D}/bad.tum --annotations {A0} {D}/bad.csv --out {OUT}",
       {"bad.tum: got 1 frames", "min_segment_length = 60"},
       {{"bad.tum", "0 0 0 0 0 0 0 1\n"}, {"bad.csv", AnnotationLines(1)}}},
      {"tum: shorter than the minimum segment",
       "compose --takes {T0} {D}/bad.tum --annotations {A0} {D}/bad.csv --out {OUT}",
       {"bad.tum: got 40 frames", "more than montage.labelling.min_segment_length = 60"},
       {{"bad.tum", TakeLines(40, 0)}, {"bad.csv", AnnotationLines(40)}}},
      {"tum: empty", ComposeTake("{D}/bad.tum"), {"bad.tum: got no poses"}, {{"bad.tum", ""}}},
      {"tum: only comments",
       ComposeTake("{D}/bad.tum"),
       {"bad.tum: got no poses"},
       {{"bad.tum", "# timestamp tx ty tz qx qy qz qw\n#\n"}}},
      {"tum: binary garbage",
       ComposeTake("{D}/bad.tum"),
       {"bad.tum: got binary data (a NUL byte at offset 7)", "expected a UTF-8 text file"},
       {{"bad.tum", garbage}}},
      {"tum: UTF-16",
       ComposeTake("{D}/bad.tum"),
       {"bad.tum: got a UTF-16 file"},
       {{"bad.tum", utf16_take}}},
      {"tum: 1e150 m",
       ComposeTake("{D}/bad.tum"),
       {"bad.tum:1, field tx", "'1e150'", "within +-1e6 m"},
       {{"bad.tum", "0 1e150 1e150 1e150 0 0 0 1\n"}}},
      {"tum: 1e200 m",
       ComposeTake("{D}/bad.tum"),
       {"bad.tum:1, field ty", "'1e200'"},
       {{"bad.tum", "0 0 1e200 0 0 0 0 1\n"}}},
      {"tum: 1e300 m, symmetric DTW",
       ComposeTake("{D}/bad.tum") + " --set montage.dtw.step_pattern=symmetric",
       {"bad.tum:1, field tz", "'1e300'"},
       {{"bad.tum", "0 0 0 1e300 0 0 0 1\n"}}},
      {"tum: a 2 MB field",
       ComposeTake("{D}/bad.tum"),
       {"bad.tum:1", "bytes in all)"},
       {{"bad.tum", "0 0 0 0 0 0 0 " + std::string(2'000'000, '7') + "x\n"}}},
      {"tum: terminal escape",
       ComposeTake("{D}/bad.tum"),
       {"bad.tum:1, field tx", "\\x1B[2J"},
       {{"bad.tum", "0 \x1B[2J 0 0 0 0 0 1\n"}}},
      {"tum: a folder", ComposeTake("{D}"), {"got a folder, expected a file"}},
      {"tum: missing", ComposeTake("{D}/none.tum"), {"none.tum: got a path that does not exist"}},
      {"tum: second line bad",
       ComposeTake("{D}/bad.tum"),
       {"bad.tum:2, field qx", "'--1'"},
       {{"bad.tum", "0 0 0 0 0 0 0 1\n0.1 0 0 0 --1 0 0 1\n"}}},
      {"tum: take of another length, time_warp off",
       ComposeWith("--set montage.time_warp=false"),
       {"t1.tum: got 220 frames", "200 frames like", "time_warp = false"}},

      // ---- Annotations (CSV) ------------------------------------------------------------------
      {"csv: wrong header",
       ComposeAnnotation("{D}/bad.csv"),
       {"bad.csv:1", "the header 'time,value'", "expected the header 'timestamp,value'"},
       {{"bad.csv", "time,value\n0,1\n"}}},
      {"csv: no header",
       ComposeAnnotation("{D}/bad.csv"),
       {"bad.csv:1", "the header '0,1'"},
       {{"bad.csv", "0,1\n"}}},
      {"csv: semicolons",
       ComposeAnnotation("{D}/bad.csv"),
       {"bad.csv:1", "'timestamp;value'"},
       {{"bad.csv", "timestamp;value\n0;1\n"}}},
      {"csv: value out of range",
       ComposeAnnotation("{D}/bad.csv"),
       {"bad.csv:3, value", "got 6", "a number in [-5, 5]"},
       {{"bad.csv", "timestamp,value\n0,1\n0.0333,6\n"}}},
      {"csv: value -inf",
       ComposeAnnotation("{D}/bad.csv"),
       {"bad.csv:2, value", "-inf"},
       {{"bad.csv", "timestamp,value\n0,-inf\n"}}},
      {"csv: value NaN",
       ComposeAnnotation("{D}/bad.csv"),
       {"bad.csv:2, value", "nan"},
       {{"bad.csv", "timestamp,value\n0,nan\n"}}},
      {"csv: value text",
       ComposeAnnotation("{D}/bad.csv"),
       {"bad.csv:2, value", "'high'"},
       {{"bad.csv", "timestamp,value\n0,high\n"}}},
      {"csv: three fields",
       ComposeAnnotation("{D}/bad.csv"),
       {"bad.csv:2", "3 fields", "2 fields: timestamp,value"},
       {{"bad.csv", "timestamp,value\n0,1,2\n"}}},
      {"csv: one field",
       ComposeAnnotation("{D}/bad.csv"),
       {"bad.csv:2", "1 fields"},
       {{"bad.csv", "timestamp,value\n0\n"}}},
      {"csv: empty",
       ComposeAnnotation("{D}/bad.csv"),
       {"bad.csv: got an empty file"},
       {{"bad.csv", ""}}},
      {"csv: header only",
       ComposeAnnotation("{D}/bad.csv"),
       {"bad.csv: got a header but no rows"},
       {{"bad.csv", "timestamp,value\n"}}},
      {"csv: length mismatch",
       ComposeAnnotation("{D}/bad.csv"),
       {"bad.csv: got 200 rows", "220 rows, one per frame of", "t1.tum"},
       {{"bad.csv", AnnotationLines(200)}}},
      {"csv: milliseconds",
       ComposeAnnotation("{D}/bad.csv"),
       {"bad.csv, row 2, timestamp", "got 33.3", "the timestamp of frame 1 of", "t1.tum"},
       {{"bad.csv", AnnotationLines(220, 1000.0)}}},
      {"csv: shifted by 1000 s",
       ComposeAnnotation("{D}/bad.csv"),
       {"bad.csv, row 1, timestamp", "got 1000", "the timestamp of frame 0"},
       {{"bad.csv", AnnotationLines(220, 1.0, 1000.0)}}},
      {"csv: unsorted",
       ComposeAnnotation("{D}/bad.csv"),
       {"bad.csv:3, timestamp", "greater than the previous timestamp 1"},
       {{"bad.csv", "timestamp,value\n1,0\n0.5,0\n"}}},
      {"csv: UTF-16",
       ComposeAnnotation("{D}/bad.csv"),
       {"bad.csv: got a UTF-16 file"},
       {{"bad.csv", std::string("\xFF\xFEt\0i\0m\0e\0", 10)}}},
      {"csv: binary",
       ComposeAnnotation("{D}/bad.csv"),
       {"bad.csv: got binary data"},
       {{"bad.csv", garbage}}},
      {"csv: a 2 MB value",
       ComposeAnnotation("{D}/bad.csv"),
       {"bad.csv:2, value", "bytes in all)"},
       {{"bad.csv", "timestamp,value\n0," + std::string(2'000'000, '9') + "q\n"}}},
      {"csv: missing", ComposeAnnotation("{D}/none.csv"), {"none.csv: got a path that does not"}},
      {"csv: too few annotations",
       "compose --takes {T0} {T1} --annotations {A0} --out {OUT}",
       {"--annotations: got 1 files for 2 takes"}},

      // ---- Configs and --set ------------------------------------------------------------------
      {"config: malformed",
       ComposeWith("--config {D}/c.json"),
       {"c.json:2:", "invalid JSON"},
       {{"c.json", "{\"montage\": {\n  \"dtw\": ,\n}}"}}},
      {"config: trailing comma",
       ComposeWith("--config {D}/c.json"),
       {"c.json:1:", "invalid JSON"},
       {{"c.json", "{\"montage\": {},}"}}},
      {"config: misspelt key",
       ComposeWith("--config {D}/c.json"),
       {"c.json", "montage.labeling", "unknown", "labelling"},
       {{"c.json", "{\"montage\": {\"labeling\": {}}}"}}},
      {"config: misspelt section",
       ComposeWith("--config {D}/c.json"),
       {"c.json", "section 'montag' is unknown", "did you mean 'montage'"},
       {{"c.json", "{\"montag\": {}}"}}},
      {"config: wrong type",
       ComposeWith("--config {D}/c.json"),
       {"c.json", "montage.dtw.lambda", "\"x\"", "a number"},
       {{"c.json", "{\"montage\": {\"dtw\": {\"lambda\": \"x\"}}}"}}},
      {"config: bool for a number",
       ComposeWith("--config {D}/c.json"),
       {"c.json", "montage.blend.window", "true"},
       {{"c.json", "{\"montage\": {\"blend\": {\"window\": true}}}"}}},
      {"config: duplicate section",
       ComposeWith("--config {D}/c.json"),
       {"c.json: key 'montage'", "appears twice"},
       {{"c.json", "{\"montage\": {\"dtw\": {}}, \"montage\": {}}"}}},
      {"config: duplicate key",
       ComposeWith("--config {D}/c.json"),
       {"c.json: key 'montage.dtw.lambda'", "appears twice"},
       {{"c.json", "{\"montage\": {\"dtw\": {\"lambda\": 1, \"lambda\": 2}}}"}}},
      {"config: empty",
       ComposeWith("--config {D}/c.json"),
       {"c.json:1:1", "invalid JSON"},
       {{"c.json", ""}}},
      {"config: a folder", ComposeWith("--config {D}"), {"got a folder, expected a file"}},
      {"config: /dev/zero", ComposeWith("--config /dev/zero"), {"/dev/zero: got binary data"}},
      {"config: UTF-16",
       ComposeWith("--config {D}/c.json"),
       {"c.json: got a UTF-16 file"},
       {{"c.json", std::string("\xFF\xFE{\0}\0", 6)}}},
      {"config: binary",
       ComposeWith("--config {D}/c.json"),
       {"c.json: got binary data"},
       {{"c.json", garbage}}},
      {"config: an array",
       ComposeWith("--config {D}/c.json"),
       {"c.json: got a JSON array", "a JSON object"},
       {{"c.json", "[1, 2]"}}},
      {"config: a number",
       ComposeWith("--config {D}/c.json"),
       {"c.json: got a JSON number"},
       {{"c.json", "3"}}},
      {"config: missing",
       ComposeWith("--config {D}/none.json"),
       {"none.json: got a path that does not exist"}},
      {"config: huge number",
       ComposeWith("--config {D}/c.json"),
       {"c.json", "a number a double can hold"},
       {{"c.json", "{\"montage\": {\"dtw\": {\"lambda\": 1e999}}}"}}},
      {"set: NaN",
       ComposeWith("--set montage.dtw.lambda=NaN"),
       {"montage.dtw.lambda", "NaN", "a number"}},
      {"set: Inf",
       ComposeWith("--set montage.dtw.lambda=1e999"),
       {"--set montage.dtw.lambda=1e999", "montage.dtw.lambda",
        "got \"1e999\", expected a number"}},
      {"set: negative",
       ComposeWith("--set montage.dtw.lambda=-1"),
       {"montage.dtw.lambda: got -1", ">= 0"}},
      {"set: huge window",
       ComposeWith("--set montage.blend.window=1000000001"),
       {"montage.blend.window", "1000000001"}},
      {"set: negative segment length",
       ComposeWith("--set montage.labelling.min_segment_length=-5"),
       {"montage.labelling.min_segment_length", "-5"}},
      {"set: misspelt key",
       ComposeWith("--set montage.labelling.muu=3"),
       {"montage.labelling.muu", "unknown", "did you mean 'mu'"}},
      {"set: unknown enum",
       ComposeWith("--set montage.dtw.step_pattern=diagonal"),
       {"montage.dtw.step_pattern", "diagonal", "literal"}},
      {"set: no '='",
       ComposeWith("--set montage.dtw.lambda"),
       {"--set montage.dtw.lambda", "key.path=value"}},
      {"set: empty key", ComposeWith("--set montage..lambda=1"), {"an empty key"}},
      {"set: key in a number",
       ComposeWith("--set montage.dtw.lambda=1 --set montage.dtw.lambda.x=2"),
       {"--set montage.dtw.lambda.x=2", "a key inside a non-object value"}},
      {"set: duplicate keys",
       ComposeWith("--set 'montage.dtw={\"lambda\": 1, \"lambda\": 2}'"),
       {"key 'lambda'", "appears twice"}},
      {"set: unknown section",
       ComposeWith("--set render.frames=3"),
       {"section 'render' is unknown", "this command reads: montage"}},

      // ---- Flags and outputs ------------------------------------------------------------------
      {"flag: unknown", ComposeWith("--bogus"), {"--bogus"}},
      {"flag: missing --takes",
       "compose --annotations {A0} {A1} --out {OUT}",
       {"--takes is required"}},
      {"flag: missing --out",
       "compose --takes {T0} {T1} --annotations {A0} {A1}",
       {"--out is required"}},
      {"flag: --out ''",
       "compose --takes {T0} {T1} --annotations {A0} {A1} --out ''",
       {"--out: got an empty path", "the path of an output folder"}},
      {"flag: --out=",
       "compose --takes {T0} {T1} --annotations {A0} {A1} --out=",
       {"--out: got an empty path"}},
      {"flag: --threads 0",
       ComposeWith("--threads 0"),
       {"--threads: got 0", "an integer from 1 to 1024"}},
      {"flag: --threads -1", ComposeWith("--threads -1"), {"--threads: got '-1'"}},
      {"flag: --threads 100000", ComposeWith("--threads 100000"), {"--threads: got 100000"}},
      {"flag: --threads=abc", ComposeWith("--threads=abc"), {"--threads: got 'abc'"}},
      {"flag: --threads 1.5 for render",
       "render --threads 1.5 --out {OUT}",
       {"--threads: got '1.5'"}},
      {"flag: unknown subcommand",
       "composee --out {OUT}",
       {"mmh: got the unknown subcommand 'composee'", "compose"}},
      {"flag: --markers text", ComposeWith("--markers ten"), {"--markers", "ten"}},
      {"flag: a 100 kB argument", ComposeWith("--bogus=" + std::string(100'000, 'b')), {"--bogus"}},
      {"out: an existing file",
       ComposeWith(""),
       {"out.txt: got an existing file"},
       {{"out.txt", "keep me"}},
       nullptr,
       "{D}/out.txt"},
      {"out: a folder of other files",
       ComposeWith(""),
       {"theirs: got an existing folder that mmh did not write"},
       {{"theirs/notes.txt", "mine"}},
       nullptr,
       "{D}/theirs"},
      {"out: parent is a file",
       ComposeWith(""),
       {"parent/out: got a parent folder that cannot"},
       {{"parent", "a file"}},
       nullptr,
       "{D}/parent/out"},
      {"out: unwritable parent",
       ComposeWith(""),
       {"/proc/mmh-bad-input"},
       {},
       nullptr,
       "/proc/mmh-bad-input/out"},

      // ---- Study CSVs (mmh stats) -------------------------------------------------------------
      {"stats: ranks not a permutation",
       "stats --input {D}/s --out {OUT}",
       {"rankings.csv:2, column 'rank'", "ranks 4, 4, 3, 1", "a permutation of 1..4"}},
      {"stats: missing item", "stats --input {D}/s --out {OUT}", {"rankings.csv", "A01"}},
      {"stats: non-binary preference",
       "stats --input {D}/s --out {OUT}",
       {"comparisons.csv:2", "montage_preferred", "2"}},
      {"stats: missing column",
       "stats --input {D}/s --out {OUT}",
       {"comparisons.csv:1", "montage_preferred"}},
      {"stats: cost row of an unknown animator",
       "stats --input {D}/s --out {OUT}",
       {"segment_costs.csv:2, column 'animator'", "'A99'", "an animator of"}},
      {"stats: rankings missing", "stats --input {D}/s --out {OUT}", {"rankings.csv"}},
      {"stats: rankings empty", "stats --input {D}/s --out {OUT}", {"rankings.csv"}},
      {"stats: NaN rank",
       "stats --input {D}/s --out {OUT}",
       {"rankings.csv:2", "column 'rank'", "nan"}},
      {"stats: duplicate ranking",
       "stats --input {D}/s --out {OUT}",
       {"rankings.csv:", "a second rank of item 'take1' by animator 'A01'"}},
      {"stats: take 0",
       "stats --input {D}/s --out {OUT}",
       {"comparisons.csv:2, column 'take'", "got '0'", "a take number 1, 2"}},
      {"stats: UTF-16 rankings",
       "stats --input {D}/s --out {OUT}",
       {"rankings.csv: got a UTF-16 file"}},
      {"stats: misspelt key",
       "stats --input {STUDY} --out {OUT} --set stats.chanse=0.4",
       {"stats.chanse", "did you mean 'chance'"}},
      {"stats: no input folder", "stats --input {D}/none --out {OUT}", {"none"}},

      // ---- check-paper --------------------------------------------------------------------------
      {"check-paper: binary paper",
       "check-paper --paper {D}/paper.pdf --out {OUT}",
       {"paper.pdf: got binary data"},
       {{"paper.pdf", "%PDF-1.5\n" + garbage}}},
      {"check-paper: UTF-16 paper",
       "check-paper --paper {D}/paper.txt --out {OUT}",
       {"paper.txt: got a UTF-16 file"},
       {{"paper.txt", std::string("\xFF\xFEM\0o\0", 6)}}},
      {"check-paper: malformed reported",
       "check-paper --reported {D}/r.json --out {OUT}",
       {"r.json:1:7: invalid JSON"},
       {{"r.json", "{\"a\": }"}}},
      {"check-paper: duplicate keys",
       "check-paper --reported {D}/r.json --out {OUT}",
       {"r.json: key", "appears twice"},
       {{"r.json", "{\"note\": \"a\", \"note\": \"b\"}"}}},
      {"check-paper: missing reported",
       "check-paper --reported {D}/none.json --out {OUT}",
       {"none.json: got a path that does not exist"}},

      // ---- render -------------------------------------------------------------------------------
      {"render: negative frames",
       "render --set render.frames=-1 --out {OUT}",
       {"render.frames: got -1", "a frame count in [1, 1000000]"}},
      {"render: 1e9 frames",
       "render --set render.frames=1000000000 --out {OUT}",
       {"render.frames: got 1000000000"}},
      {"render: 20000 x 20000 image",
       "render --set sensor.intrinsics.width=20000 --set sensor.intrinsics.height=20000 --out "
       "{OUT}",
       {"sensor.intrinsics", "20000", "[1, 16384]"}},
      {"render: unknown section",
       "render --set bogus.x=1 --out {OUT}",
       {"section 'bogus' is unknown"}},
      {"render: png compression",
       "render --set render.png_compression=12 --out {OUT}",
       {"render.png_compression", "12"}},
      {"render: lattice search on another lattice",
       "render --set sensor.structured_light.lattice_search=true "
       "--set sensor.calibration.subpixel_steps=4 --out {OUT}",
       {"sensor.structured_light.lattice_search: got true", "calibration.subpixel_steps 4"}},
      {"render: NaN frame rate",
       "render --set sensor.frame_rate=NaN --out {OUT}",
       {"sensor.frame_rate", "NaN"}},
      {"render: story missing",
       "render --set scenario.story=/nonexistent/story.json --out {OUT}",
       {"/nonexistent/story.json"}},
      {"render: story with a repeated key",
       "render --set scenario.story={D}/s.json --out {OUT}",
       {"s.json: key 'objects[0].name'", "appears twice"},
       {{"s.json", R"({"name": "x", "objects": [{"name": "a", "name": "b"}]})"}}},

      {"render: scene object's mesh missing (relative to its config file)",
       "render --config {D}/scene.json --out {OUT}",
       {"scene.objects[0].mesh (mug)", "models/mug.obj"},
       {{"scene.json", R"({"scene": {"objects": [{"name": "mug", "mesh": "models/mug.obj"}]}})"}}},
      {"render: scene object named like the scene's own",
       "render --config {D}/scene.json --out {OUT}",
       {"scene.objects[0].name: got \"table\""},
       {{"scene.json",
         R"({"scene": {"objects": [{"name": "table", "mesh": "{RGBD}/model.ply"}]}})"}}},
      {"render: scene object's quaternion not unit",
       "render --config {D}/scene.json --out {OUT}",
       {"scene.objects[0].qx, qy, qz, qw", "norm 2"},
       {{"scene.json",
         R"({"scene": {"objects": [{"name": "m", "mesh": "{RGBD}/model.ply", "qw": 2}]}})"}}},
      {"render: the table top turned so that the play area leaves it",
       "render --config {D}/scene.json --out {OUT}",
       {"scene.play_area_", "turned 30 deg"},
       {{"scene.json", R"({"scene": {"table_y": 0.5, "table_yaw_deg": 30, "backdrop": false}})"}}},
      {"render: the camera rolled beyond a half turn",
       "render --config {D}/scene.json --out {OUT}",
       {"camera.roll_deg: got -181", "[-180, 180]"},
       {{"scene.json", R"({"camera": {"roll_deg": -181}})"}}},
      {"render: the table top turned beyond a half turn",
       "render --config {D}/scene.json --out {OUT}",
       {"scene.table_yaw_deg: got 270", "[-180, 180]"},
       {{"scene.json", R"({"scene": {"table_yaw_deg": 270}})"}}},
      {"render: scene objects not a list",
       "render --config {D}/scene.json --out {OUT}",
       {"scene.json: key 'scene.objects'", "an array of objects"},
       {{"scene.json", R"({"scene": {"objects": {"name": "m"}}})"}}},
      {"sensor-check: more view frames than the recording has",
       "sensor-check --frames 1 --view-frames 11 --out {OUT}",
       {"0000: frames: got 10", "at least 11 frames"}},
      {"sensor-check: a view label without a frame number",
       "sensor-check --frames 1 --view-frames 2 --view-label {D}/label.png --out {OUT}",
       {"label.png: name"},
       {},
       [](const fs::path& d) {
         fs::copy_file(fs::path(MMH_SOURCE_DIR) / "tests/data/real/ycbv/data/0000/000001-label.png",
                       d / "label.png");
       }},

      // ---- track (RGB-D folders, meshes, camera.json) ------------------------------------------
      {"track: input missing",
       "track --input {D}/none --model {RGBD}/model.ply --out {OUT}",
       {"none"}},
      {"track: depth.txt missing",
       "track --input {D}/in --model {RGBD}/model.ply --out {OUT}",
       {"depth.txt"},
       {},
       CopyRgbd(fx.rgbd, [](const fs::path& in) { fs::remove(in / "depth.txt"); })},
      {"track: rgb.txt garbage",
       "track --input {D}/in --model {RGBD}/model.ply --out {OUT}",
       {"rgb.txt"},
       {},
       CopyRgbd(fx.rgbd, [](const fs::path& in) { WriteText(in / "rgb.txt", "0 x y z\n"); })},
      {"track: 8-bit depth PNGs",
       "track --input {D}/in --model {RGBD}/model.ply --out {OUT}",
       {"in: got no readable frame among 3", "in/depth/0.0000"},
       {},
       CopyRgbd(fx.rgbd,
                [](const fs::path& in) {
                  for (const fs::path& f : DepthImages(in)) {
                    RgbImage image;
                    image.width = 640;
                    image.height = 480;
                    image.rgb.assign(640 * 480 * 3, 100);
                    WriteRgbPng(f, image);
                  }
                })},
      {"track: truncated depth PNGs",
       "track --input {D}/in --model {RGBD}/model.ply --out {OUT}",
       {"in: got no readable frame among 3", "in/depth/0.0000"},
       {},
       CopyRgbd(fx.rgbd,
                [](const fs::path& in) {
                  for (const fs::path& f : DepthImages(in)) {
                    const std::string bytes = ReadBytes(f);
                    WriteText(f, bytes.substr(0, bytes.size() / 2));
                  }
                })},
      {"track: wrong-size depth PNGs",
       "track --input {D}/in --model {RGBD}/model.ply --out {OUT}",
       {"in: got no readable frame among 3"},
       {},
       CopyRgbd(fx.rgbd,
                [](const fs::path& in) {
                  for (const fs::path& f : DepthImages(in)) {
                    DepthImage image;
                    image.width = 320;
                    image.height = 240;
                    image.values.assign(320 * 240, 5000);
                    WriteDepthPng16(f, image);
                  }
                })},
      {"track: camera.json duplicate key",
       "track --input {D}/in --model {RGBD}/model.ply --out {OUT}",
       {"camera.json: key 'depth_scale'", "appears twice"},
       {},
       CopyRgbd(fx.rgbd,
                [](const fs::path& in) {
                  std::string text = ReadBytes(in / "camera.json");
                  text.insert(text.find('{') + 1, "\"depth_scale\": 1,");
                  WriteText(in / "camera.json", text);
                })},
      {"track: camera.json malformed",
       "track --input {D}/in --model {RGBD}/model.ply --out {OUT}",
       {"camera.json:1:", "invalid JSON"},
       {},
       CopyRgbd(fx.rgbd, [](const fs::path& in) { WriteText(in / "camera.json", "{\"a\""); })},
      {"track: model missing",
       "track --input {RGBD} --model {D}/none.ply --out {OUT}",
       {"none.ply"}},
      {"track: model empty",
       "track --input {RGBD} --model {D}/m.ply --out {OUT}",
       {"m.ply"},
       {{"m.ply", ""}}},
      {"track: model malformed",
       "track --input {RGBD} --model {D}/m.ply --out {OUT}",
       {"m.ply"},
       {{"m.ply", "ply\nformat ascii 1.0\nelement vertex 3\nend_header\n0 0\n"}}},
      {"track: model NaN vertices",
       "track --input {RGBD} --model {D}/m.obj --out {OUT}",
       {"m.obj", "nan"},
       {{"m.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n"}}},
      {"track: model with no faces",
       "track --input {RGBD} --model {D}/m.obj --out {OUT}",
       {"m.obj"},
       {{"m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n"}}},
      // A fuzz finding: Debian's assimp 5 aborted on this PLY (exit 134); mmh reads PLY itself.
      {"export: model PLY with letters in its values",
       "export --trajectory {T0} --model {D}/m.ply --out {D}/m.glb",
       {"m.ply:10: vertex 0", "'0i'", "a number of type float"},
       {{"m.ply",
         "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
         "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
         "0 0 0i 1.001 0 i1 2\n"}}},
      {"export: model binary PLY cut short",
       "export --trajectory {T0} --model {D}/m.ply --out {D}/m.glb",
       {"m.ply:3: got element 'vertex' of 3 items", "16 bytes after the header"},
       {{"m.ply",
         "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
         "property float y\nproperty float z\nend_header\n0123456789ab0123"}}},
      {"export: model OBJ face index out of range",
       "export --trajectory {T0} --model {D}/m.obj --out {D}/m.glb",
       {"m.obj:4: f, corner 3", "vertex index '7'", "from 1 to 3"},
       {{"m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n"}}},
      {"track: unknown key",
       "track --input {RGBD} --model {RGBD}/model.ply --out {OUT} "
       "--set tracker.bogus=1",
       {"tracker.bogus", "unknown"}},
      {"track: setup malformed",
       "track --input {RGBD} --model {RGBD}/model.ply --setup {D}/s.json --out {OUT}",
       {"s.json"},
       {{"s.json", "{\"camera_T_table\": "}}},

      // ---- run, study, regress, sensor-check ---------------------------------------------------
      {"run: takes shorter than the minimum segment",
       "run --config {SRC}/configs/soldier.json --set render.frames=5 --out {OUT}",
       {"render.frames: got 5", "more than montage.labelling.min_segment_length = 60"}},
      {"run: one take",
       "run --config {SRC}/configs/soldier.json --set run.takes=1 --out {OUT}",
       {"run.takes: got 1", "at least 2 takes"}},
      {"run: unknown key",
       "run --config {SRC}/configs/soldier.json --set run.bogus=1 --out {OUT}",
       {"run.bogus", "unknown"}},
      {"run: config missing",
       "run --config {D}/none.json --out {OUT}",
       {"none.json: got a path that does not exist"}},
      {"run: --threads 100000",
       "run --config {SRC}/configs/soldier.json --threads 100000 --out {OUT}",
       {"--threads: got 100000"}},
      {"study: 10^6 animators",
       "study --config {SRC}/configs/study_soldier.json --set study.animators=1000000 --out {OUT}",
       {"study.animators: got 1000000 animators", "at most 100000 animators"}},
      {"study: 2 animators",
       "study --config {SRC}/configs/study_soldier.json --set study.animators=2 --out {OUT}",
       {"study.animators: got 2", "at least 3"}},
      {"study: unknown section",
       "study --config {SRC}/configs/study_soldier.json --set studdy.x=1 --out {OUT}",
       {"section 'studdy' is unknown"}},
      {"regress: baseline missing", "regress --baseline {D}/none --out {OUT}", {"none"}},
      {"regress: baseline malformed",
       "regress --baseline {D}/b --out {OUT}",
       {"baseline.json"},
       {{"b/baseline.json", "{\"scenarios\": [}"}}},
      // (A config_hash of another type used to escape as nlohmann's type_error: exit 1.)
      {"regress: config_hash not a string",
       "regress --baseline {D}/b --out {OUT}",
       {"b/baseline.json: scenarios[0].config_hash", "7", "a hash string"},
       {{"b/baseline.json",
         R"({"root": ".", "scenarios": [{"name": "a", "config": "c.json", "config_hash": 7,)"
         R"( "metrics": {}}]})"}}},
      // ---- sweep (spec, and the plan of an earlier sweep) --------------------------------------
      {"sweep: spec with a repeated key",
       "sweep --spec {D}/s.json --out {OUT} --dry-run",
       {"s.json", "key 'command'", "twice"},
       {{"s.json", "{\"command\": \"compose\", \"command\": \"run\", \"axes\": []}"}}},
      {"sweep: spec cut short",
       "sweep --spec {D}/s.json --out {OUT} --dry-run",
       {"s.json:2:", "invalid JSON"},
       {{"s.json", "{\"command\": \"compose\",\n \"axes\": [{\"key\": \"montage"}}},
      {"sweep status: plan.json with a repeated key",
       "sweep status {D}/sw",
       {"plan.json", "key 'format'", "twice"},
       {{"sw/plan.json", "{\"format\": \"mmh-sweep-plan-1\", \"format\": \"x\"}"}}},
      {"sensor-check: data missing", "sensor-check --data {D}/none --out {OUT}", {"none"}},
      {"sensor-check: Kinect sequence missing",
       "sensor-check --frames 1 --kinect-sequence {D}/none --out {OUT}",
       {"none: got no such folder", "a TUM RGB-D folder (depth.txt)"}},
      {"sensor-check: Kinect sequence folder of no known layout",
       "sensor-check --frames 1 --kinect-sequence {D}/empty_sequence --out {OUT}",
       {"empty_sequence: got a folder of no known layout", "a TUM RGB-D folder (depth.txt)",
        "a BOP scene", "a YCB-Video folder"},
       {{"empty_sequence/notes.txt", "not a recording\n"}}},
      {"sensor-check: Kinect sequence listing an image it lacks",
       "sensor-check --frames 1 --kinect-sequence {D}/rgbd_dataset_freiburg1_x --out {OUT}",
       {"rgbd_dataset_freiburg1_x/rgb.txt:2", "rgb/a.png", "does not exist"},
       {{"rgbd_dataset_freiburg1_x/rgb.txt", "# rgb\n1.0 rgb/a.png\n"},
        {"rgbd_dataset_freiburg1_x/depth.txt", "# depth\n1.0 depth/a.png\n"}}},
      {"sensor-check: view object absent",
       "sensor-check --view-object 99 --out {OUT}",
       {"000001-label.png: object", "got 99", "a label the image holds"}},
      {"sensor-check: view choosing its sensor",
       "sensor-check --view {D}/v.json --out {OUT}",
       {"v.json: sensor", "the sensor under test"},
       {{"v.json", "{\"sensor\": {\"mode\": \"statistical\"}}"}}},
      {"sensor-check: view object out of sight",
       "sensor-check --view-trajectory {D}/away.tum --out {OUT}",
       {"the object in the rendered view: got not seen", "the camera's view"},
       {{"away.tum", "0 0 0 -50 0 0 0 1\n"}}},
      {"sensor-check: view without a sequence",
       "sensor-check --sequence '' --out {OUT}",
       {"--view", "a --sequence whose first frame it shows"}},
  };

  // Study CSV damage: a copy of the example with one file changed.
  auto study_case = [&](const std::string& name, std::function<void(const fs::path&)> damage) {
    for (BadInput& b : c) {
      if (b.name == name) {
        const fs::path example = fx.dir / "study";
        b.setup = [example, damage](const fs::path& d) {
          fs::copy(example, d / "s");
          damage(d / "s");
        };
      }
    }
  };
  auto edit = [](const fs::path& file, const std::string& from, const std::string& to) {
    std::string text = ReadBytes(file);
    const std::size_t pos = text.find(from);
    ASSERT_NE(pos, std::string::npos) << from;
    text.replace(pos, from.size(), to);
    WriteText(file, text);
  };
  study_case("stats: ranks not a permutation",
             [&](const fs::path& s) { edit(s / "rankings.csv", "A01,take2,2", "A01,take2,4"); });
  study_case("stats: missing item",
             [&](const fs::path& s) { edit(s / "rankings.csv", "A01,take2,2\n", ""); });
  study_case("stats: non-binary preference",
             [&](const fs::path& s) { edit(s / "comparisons.csv", "A01,A02,1,1", "A01,A02,1,2"); });
  study_case("stats: missing column", [&](const fs::path& s) {
    WriteText(s / "comparisons.csv", "scorer,animator,take\nA01,A02,1\n");
  });
  study_case("stats: cost row of an unknown animator",
             [&](const fs::path& s) { edit(s / "segment_costs.csv", "A01,", "A99,"); });
  study_case("stats: rankings missing", [](const fs::path& s) { fs::remove(s / "rankings.csv"); });
  study_case("stats: rankings empty", [](const fs::path& s) { WriteText(s / "rankings.csv", ""); });
  study_case("stats: NaN rank",
             [&](const fs::path& s) { edit(s / "rankings.csv", "A01,take1,4", "A01,take1,nan"); });
  study_case("stats: duplicate ranking", [&](const fs::path& s) {
    edit(s / "rankings.csv", "A01,take2,2\n", "A01,take2,2\nA01,take1,4\n");
  });
  study_case("stats: take 0",
             [&](const fs::path& s) { edit(s / "comparisons.csv", "A01,A02,1,1", "A01,A02,0,1"); });
  study_case("stats: UTF-16 rankings", [](const fs::path& s) {
    WriteText(s / "rankings.csv", std::string("\xFF\xFE"
                                              "a\0n\0",
                                              6));
  });
  return c;
}

TEST(BadInputCorpus, EveryBadInputExitsTwoWithAClearMessageAndLeavesNothing) {
  Fixture fx;
  ASSERT_TRUE(fs::exists(fx.rgbd / "depth.txt"));
  const std::vector<BadInput> corpus = Corpus(fx);
  EXPECT_GE(corpus.size(), 100u);
  TempDir root;
  int index = 0;
  // MMH_BAD_INPUT_FILTER=text runs only the cases whose name holds it (while fixing one).
  const char* filter = std::getenv("MMH_BAD_INPUT_FILTER");
  for (const BadInput& b : corpus) {
    if (filter && b.name.find(filter) == std::string::npos) continue;
    SCOPED_TRACE(b.name);
    const fs::path d = root / ("case_" + std::to_string(index++));
    fs::create_directories(d);
    auto values = fx.Values(d);
    const std::string out = Replace(b.out, values);
    values["{OUT}"] = out;
    for (const auto& [name, contents] : b.files) {
      fs::create_directories((d / name).parent_path());
      WriteText(d / name, contents);
    }
    if (b.setup) b.setup(d);
    // What is there before the run (an existing --out file or folder is part of some cases).
    std::vector<std::string> before;
    for (const auto& e : fs::recursive_directory_iterator(d)) before.push_back(e.path().string());
    std::sort(before.begin(), before.end());
    const std::string before_out = fs::is_regular_file(out) ? ReadBytes(out) : "";

    const Outcome o = RunCommand(Replace(b.args, values));
    EXPECT_EQ(o.exit_code, 2) << (o.exit_code == 124  ? "hang"
                                  : o.exit_code > 128 ? "crash"
                                                      : "")
                              << "\n"
                              << o.output.substr(0, 2000);
    for (const std::string& part : b.expect) {
      EXPECT_NE(o.output.find(Replace(part, values)), std::string::npos)
          << "'" << part << "' not in:\n"
          << o.output.substr(0, 2000);
    }
    // Short and one error: never the whole input echoed back.
    EXPECT_LT(o.output.size(), 1500u) << o.output.substr(0, 2000);
    EXPECT_NE(o.output.find("error"), std::string::npos) << o.output.substr(0, 2000);
    // Nothing written: the case folder holds what it held, an existing --out is unchanged.
    std::vector<std::string> after;
    for (const auto& e : fs::recursive_directory_iterator(d)) after.push_back(e.path().string());
    std::sort(after.begin(), after.end());
    EXPECT_EQ(after, before);
    if (!before_out.empty()) EXPECT_EQ(ReadBytes(out), before_out);
    if (b.out == "{D}/out") EXPECT_FALSE(fs::exists(out));
  }
}

}  // namespace
}  // namespace mmh
