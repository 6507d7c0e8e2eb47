// The exactgeo command as a whole: help and version, exit codes and messages for bad input, list options and
// list files, output files (kept on failure, removed on interruption, FIFOs, links, stdout), and threads.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "exactgeo/exactgeo.hpp"
#include "exactgeo/version.hpp"

#include "cli_run.hpp"

namespace {

using namespace exactgeo_test;

TEST_F(Cli, VersionPrintsTheLibraryVersion) {
  const RunResult result = run("--version");
  EXPECT_EQ(result.exit_code, 0);
  EXPECT_NE(result.out.find(exactgeo::kVersion), std::string::npos) << result.out;
}

TEST_F(Cli, HelpExitsZero) {
  const RunResult result = run("distance --help");
  EXPECT_EQ(result.exit_code, 0);
  EXPECT_NE(result.out.find("@icosphere:K"), std::string::npos) << result.out;
}

TEST_F(Cli, MissingFileIsInvalidInput) {
  expect_error(run("distance " + arg("no-such-mesh.obj") + " --source 0"), 2, "no-such-mesh.obj");
  expect_error(run("info " + arg("no-such-mesh.ply")), 2, "no-such-mesh.ply");
}

// A link to /dev/zero was read until memory ran out, and a FIFO waited for a writer forever.
TEST_F(Cli, NonRegularFilesAreInvalidInput) {
  fs::create_symlink("/dev/zero", path("zero.obj"));
  fs::create_directory(path("folder.ply"));
  ASSERT_EQ(::mkfifo(path("pipe.off").c_str(), 0600), 0);
  for (const char* name : {"zero.obj", "folder.ply", "pipe.off"}) {
    expect_error(run("distance " + arg(name) + " --source 0"), 2, path(name).string() + "': not a regular file");
    expect_error(run("info " + arg(name)), 2, path(name).string() + "': not a regular file");
  }
}

TEST_F(Cli, MalformedObjIsInvalidInput) {
  write_file(path("bad-index.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
  expect_error(run("distance " + arg("bad-index.obj") + " --source 0"), 2, "bad-index.obj");
  write_file(path("bad-number.obj"), "v 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n");
  expect_error(run("info " + arg("bad-number.obj")), 2, "bad-number.obj");
}

TEST_F(Cli, SourceOutOfRangeIsInvalidInput) {
  expect_error(run("distance @icosphere:1 --source 42"), 2, "42");
  expect_error(run("distance @icosphere:1 --source 99999999999"), 2, "99999999999");
}

TEST_F(Cli, BuiltinParameterOutOfRangeIsInvalidInput) {
  expect_error(run("info @grid:0:4"), 2, "grid");
  // Level 14 was accepted and grew until memory ran out: its faces do not fit 32-bit indices.
  expect_error(run("info @icosphere:14"), 2, "icosphere subdivisions 14 out of range (0 to 13");
}

TEST_F(Cli, UsageErrors) {
  expect_error(run("distance @icosphere:1 --source 0 --frobnicate"), 1, "--frobnicate");
  expect_error(run("distance @icosphere:1"), 1, "--source");
  expect_error(run("distance @icosphere:1 --source-point 3:0.2,0.3"), 1, "3:0.2,0.3");
  expect_error(run("distance @icosphere:1 --source 0 --max-distance -2"), 1, "-2");
  expect_error(run("path @icosphere:1 --source 0"), 1, "--target");
  expect_error(run("path @icosphere:1 --source 0 --target 3 --out " + arg("p.txt")), 1, "p.txt");
  expect_error(run("distance @icosphere:1 --source -1"), 1, "-1");
  expect_error(run("distance @icosphere:1 --source abc"), 1, "abc");
  expect_error(run("distance @cube --source 0"), 1, "@cube");
  expect_error(run("frobnicate"), 1, "frobnicate");
  expect_error(run(""), 1, "subcommand");
}

TEST_F(Cli, BadOutputExtensionIsUsageError) {
  expect_error(run("distance @icosphere:1 --source 0 --out " + arg("d.xyz")), 1, "d.xyz");
  expect_error(run("distance @icosphere:1 --source 0 --out " + arg("no-extension")), 1, "no-extension");
  EXPECT_FALSE(fs::exists(path("d.xyz")));
}

TEST_F(Cli, UnwritableOutputIsInvalidInput) {
  expect_error(run("distance @icosphere:1 --source 0 --out " + arg("missing-dir/d.txt")), 2, "missing-dir/d.txt");
}

// Whether a message holds only printable ASCII and newlines: nothing of a binary file reaches the terminal.
bool printable(const std::string& message) {
  return std::all_of(message.begin(), message.end(), [](char c) { return c == '\n' || (c >= 0x20 && c < 0x7f); });
}

// matrix --sources and --targets and distance --targets read .npy arrays of every integer dtype, in either
// byte order, as the text list of the same indices.
TEST_F(Cli, ListFilesAreNpyArraysOfAnyIntegerDtype) {
  const std::vector<std::int64_t> sources = {0, 17, 100, 5};
  const std::vector<std::int64_t> targets = {33, 2, 17};
  ASSERT_EQ(run("matrix @torus:24:10 --sources 0 17 100 5 --targets 33,2,17 --out " + arg("text.npy")).exit_code, 0);
  ASSERT_EQ(run("distance @torus:24:10 --source 3 --targets 33,2,17 --target-out " + arg("text.csv")).exit_code, 0);
  for (const char* type : {"i1", "i2", "i4", "i8", "u1", "u2", "u4", "u8"})
    for (const char order : {'<', '>'}) {
      const std::string descr = (type[1] == '1' ? '|' : order) + std::string(type);
      write_file(path("s.npy"), npy_file(descr, sources));
      write_file(path("t.npy"), npy_file(descr, targets));
      RunResult result = run("matrix @torus:24:10 --sources " + arg("s.npy") + " --targets " + arg("t.npy") +
                             " --quiet --out " + arg("m.npy"));
      ASSERT_EQ(result.exit_code, 0) << descr << ": " << result.err;
      EXPECT_EQ(read_file(path("m.npy")), read_file(path("text.npy"))) << descr;
      result = run("distance @torus:24:10 --source 3 --targets " + arg("t.npy") + " --target-out " + arg("t.csv"));
      ASSERT_EQ(result.exit_code, 0) << descr << ": " << result.err;
      EXPECT_EQ(read_file(path("t.csv")), read_file(path("text.csv"))) << descr;
    }
  // Version 2.0 files (a 4-byte header length), as numpy.save writes for huge headers.
  std::string version2 = npy_file("<i4", sources);
  version2 = std::string("\x93NUMPY\x02\x00", 8) + version2.substr(8, 2) + std::string(2, '\0') + version2.substr(10);
  write_file(path("v2.npy"), version2);
  ASSERT_EQ(run("matrix @torus:24:10 --sources " + arg("v2.npy") + " --targets 33 2 17 --quiet --out " + arg("m.npy"))
                .exit_code,
            0);
  EXPECT_EQ(read_file(path("m.npy")), read_file(path("text.npy")));
}

// Lists that cannot be read are named, with the element at fault, and nothing of a binary file is printed.
TEST_F(Cli, BadListFilesAreNamedWithTheElementAndNoBinary) {
  const auto expect_list_error = [&](const std::string& file, const std::string& bytes, const std::string& expected) {
    write_file(path(file), bytes);
    for (const std::string command : {"matrix @icosphere:2 --sources " + arg(file) + " --out " + arg("m.npy"),
                                      "matrix @icosphere:2 --sources - --out " + arg("m.npy") + " < " + arg(file)}) {
      const RunResult result = run(command);
      expect_error(result, 2, expected);
      EXPECT_TRUE(printable(result.err)) << result.err;
      EXPECT_FALSE(fs::exists(path("m.npy")));
    }
    const RunResult result = run("distance @icosphere:2 --source 0 --targets " + arg(file));
    expect_error(result, 2, expected);
    EXPECT_NE(result.err.find(file), std::string::npos) << result.err;
  };
  expect_list_error("float.npy", npy_file("<f8", {0, 0x3ff0000000000000}),
                    "holds float64 values; indices must be integers");
  expect_list_error("bool.npy", npy_file("|b1", {1, 0}), "holds bool values");
  expect_list_error("two.npy", npy_file("<i4", {1, 2, 3, 4}, "(2, 2)"),
                    "array of shape (2, 2); indices must be a 1-D array");
  expect_list_error("negative.npy", npy_file("|i1", {3, -1}), "element [1] is -1, not an index");
  expect_list_error("negative64.npy", npy_file(">i8", {3, 4, -5}), "element [2] is -5, not an index");
  expect_list_error("huge.npy", npy_file("<u8", {std::int64_t{1} << 40}), "element [0] is 1099511627776, not an index");
  expect_list_error("beyond.npy", npy_file("<u2", {1, 2, 500}),
                    "element [2]: vertex 500 is out of range (mesh has 162 vertices)");
  const std::string three = npy_file("<i8", {1, 2, 3});
  expect_list_error("short.npy", three.substr(0, three.size() - 4),
                    "the header says 3 values of 8 bytes, but 20 bytes");
  expect_list_error("empty.npy", npy_file("<i8", {}), "no ");
  expect_list_error("records.npy", npy_file("<i8", {1}).replace(10, 17, "{'descr': [('a', '<i8')], "), "records");
  std::string garbage;
  for (int byte = 0; byte < 256; ++byte) garbage += char(byte);
  expect_list_error("garbage.bin", garbage, "binary data, not a list");
  expect_list_error("text.txt", "0 1 \xff\xfe\x9b", "'\\xFF\\xFE\\x9B'");
  // A text file named .npy is taken for a damaged .npy, not for a list.
  write_file(path("named.npy"), "0 1 2\n");
  expect_error(run("matrix @icosphere:2 --sources " + arg("named.npy") + " --out " + arg("m.npy")), 2,
               "not a .npy file");
  expect_error(run("matrix @icosphere:2 --sources missing.npy --out " + arg("m.npy")), 2,
               "cannot read 'missing.npy': no such file");
  // Standard input feeds one list.
  expect_error(run("matrix @icosphere:2 --sources - --targets - --out " + arg("m.npy") + " < /dev/null"), 1,
               "standard input (-) can feed one list");
  expect_error(run("matrix @icosphere:2 --sources - --out " + arg("m.npy") + " < /dev/null"), 2,
               "(standard input): no vertex given");
}

// --source, --source-point, --targets and matrix's --sources and --targets take several values, or repeat;
// MESH may come before them or after.
TEST_F(Cli, ListOptionsTakeSeveralValuesOrRepeat) {
  ASSERT_EQ(run("distance @torus:24:10 --source 0 --source 111 --labels --out " + arg("repeated.npy")).exit_code, 0);
  for (const std::string form : {"@torus:24:10 --source 0 111 --labels --out " + arg("x.npy"),
                                 "--source 0 111 @torus:24:10 --labels --out " + arg("x.npy"),
                                 "--labels --source 0 111 @torus:24:10 --out " + arg("x.npy")}) {
    const RunResult result = run("distance " + form);
    ASSERT_EQ(result.exit_code, 0) << form << ": " << result.err;
    EXPECT_EQ(read_file(path("x.npy")), read_file(path("repeated.npy"))) << form;
  }
  // Points and targets the same way.
  const std::string points = "--source-point 3:0.2,0.3,0.5 17:0.1,0.1,0.8";
  ASSERT_EQ(run("distance @torus:24:10 " + points + " --targets 5 6,7 --target-out " + arg("a.csv")).exit_code, 0);
  ASSERT_EQ(run("distance @torus:24:10 --source-point 3:0.2,0.3,0.5 --source-point 17:0.1,0.1,0.8 --targets '5 6,7' "
                "--target-out " + arg("b.csv")).exit_code, 0);
  ASSERT_EQ(run("distance " + points + " --targets 5 6 7 @torus:24:10 --target-out " + arg("c.csv")).exit_code, 0);
  EXPECT_EQ(read_file(path("a.csv")), read_file(path("b.csv")));
  EXPECT_EQ(read_file(path("a.csv")), read_file(path("c.csv")));
  // path and matrix.
  ASSERT_EQ(run("path @grid:4:4 --source 0 24 --target 12 --out " + arg("p1.json")).exit_code, 0);
  ASSERT_EQ(run("path --source 0 --source 24 @grid:4:4 --target 12 --out " + arg("p2.json")).exit_code, 0);
  EXPECT_EQ(read_file(path("p1.json")), read_file(path("p2.json")));
  ASSERT_EQ(run("matrix @icosphere:2 --sources 0 5 --sources 9 --out " + arg("m1.npy")).exit_code, 0);
  ASSERT_EQ(run("matrix --sources 0,5 9 @icosphere:2 --out " + arg("m2.npy")).exit_code, 0);
  EXPECT_EQ(read_file(path("m1.npy")), read_file(path("m2.npy")));
  // Still errors: no MESH, a value that is not a vertex.
  expect_error(run("distance --source 0 111"), 1, "MESH");
  expect_error(run("distance @grid:4:4 --source 0 x"), 1, "'x' is not a vertex index");
  expect_error(run("distance @grid:4:4 --source-point 0:1,0,0 9"), 1, "'9' is not a surface point");
  expect_error(run("distance @nothing --source 0"), 1, "unknown built-in mesh");
  expect_error(run("matrix @grid:4:4 --out " + arg("m.npy")), 1, "--sources");
}

// --out - writes CSV to stdout, with nothing else on it: the summary is left out, messages and progress go
// to stderr. Every command with a CSV format takes it.
TEST_F(Cli, OutDashWritesCsvToStdoutAlone) {
  ASSERT_EQ(run("distance @icosphere:2 --source 3 --labels --out " + arg("d.csv")).exit_code, 0);
  RunResult result = run("distance @icosphere:2 --source 3 --labels --out -");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(result.out, read_file(path("d.csv")));
  EXPECT_EQ(result.err, "");
  ASSERT_EQ(run("distance @icosphere:2 --source 3 --targets 5 9 --target-out " + arg("t.csv")).exit_code, 0);
  result = run("distance @icosphere:2 --source 3 --targets 5 9 --target-out -");
  EXPECT_EQ(result.out, read_file(path("t.csv")));
  for (const std::string command : {"matrix @icosphere:2 --sources 0 5 --targets 7 9 --out ", "sample @icosphere:2 -k 4 --out ",
                                     "path @grid:4:4 --source 0 --target 24 --out "}) {
    ASSERT_EQ(run(command + arg("x.csv")).exit_code, 0) << command;
    result = run(command + "-");
    ASSERT_EQ(result.exit_code, 0) << command << result.err;
    EXPECT_EQ(result.out, read_file(path("x.csv"))) << command;
    EXPECT_EQ(result.err, "") << command;
  }
  // Through a pipe, as a shell script uses it: the farthest vertex, and no stray output file named "-".
  const std::string pipeline = "cd '" + path("").string() + "' && '" EXACTGEO_CLI_PATH
                               "' distance @icosphere:2 --source 3 --out - 2>err | tail -n +2 | sort -t, -k2 -g | tail -1 >farthest";
  ASSERT_EQ(std::system(pipeline.c_str()), 0);
  EXPECT_EQ(read_file(path("err")), "");
  const std::string farthest = read_file(path("farthest"));
  ASSERT_EQ(run("distance @icosphere:2 --source 3 --out " + arg("plain.csv")).exit_code, 0);
  const std::vector<double> d = parse_csv(path("plain.csv"));
  EXPECT_EQ(std::strtod(farthest.c_str() + farthest.find(',') + 1, nullptr), *std::max_element(d.begin(), d.end()));
  EXPECT_FALSE(fs::exists(path("-")));
  // Binary formats need a file; two outputs cannot share stdout.
  expect_error(run("distance @icosphere:2 --source 3 --out - --target-out - --targets 5"), 1, "both");
  expect_error(run("matrix @icosphere:2 --sources 0 --out x.npz -"), 1, "");
}

// Everything is checked before an output is touched, and files are written beside their destination and
// renamed when complete: a failed run leaves an existing file as it was and no temporary file behind.
TEST_F(Cli, FailedRunsLeaveExistingOutputsUntouched) {
  const std::string kept = "an earlier result\n";
  for (const char* name : {"d.txt", "d.npy", "d.ply", "m.npy", "m.npz", "m.csv", "p.json", "s.csv"}) write_file(path(name), kept);
  expect_error(run("distance @icosphere:2 --source 9999 --out " + arg("d.txt")), 2, "9999");
  expect_error(run("distance @icosphere:2 --source 0 --targets 9999 --out " + arg("d.npy")), 2, "9999");
  expect_error(run("distance @icosphere:2 --source 0 --source-point 999:0.2,0.3,0.5 --out " + arg("d.ply")), 2, "999");
  for (const char* name : {"m.npy", "m.npz", "m.csv"})
    expect_error(run("matrix @icosphere:2 --sources 1,2,9999 --out " + arg(name)), 2, "9999");
  expect_error(run("path @icosphere:2 --source 0 --target 9999 --out " + arg("p.json")), 2, "9999");
  expect_error(run("sample @icosphere:2 -k 3 --first 9999 --out " + arg("s.csv")), 2, "9999");
  for (const char* name : {"d.txt", "d.npy", "d.ply", "m.npy", "m.npz", "m.csv", "p.json", "s.csv"})
    EXPECT_EQ(read_file(path(name)), kept) << name;
  for (const auto& entry : fs::directory_iterator(path("")))
    EXPECT_EQ(entry.path().filename().string().find(".partial"), std::string::npos) << entry.path();
}

// SIGINT, SIGTERM or SIGHUP in the middle of a run ends it at once, as the signal would, and removes the
// unfinished output: nothing is left that could be loaded as a result.
TEST_F(Cli, InterruptedRunsLeaveNoOutput) {
  for (const int signal_number : {SIGINT, SIGTERM, SIGHUP}) {
    std::string sources;
    for (int s = 0; s < 2000; ++s) sources += (s ? "," : "") + std::to_string(s);
    const std::string out = path("m.npy").string();
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      std::freopen("/dev/null", "w", stderr);
      ::execl(EXACTGEO_CLI_PATH, "exactgeo", "matrix", "@icosphere:6", "--sources", sources.c_str(), "--threads", "1",
              "--out", out.c_str(), static_cast<char*>(nullptr));
      ::_exit(127);
    }
    // Interrupt once the output is being written (the temporary file exists), at most after 60 s.
    const auto partial_exists = [&] {
      for (const auto& entry : fs::directory_iterator(path("")))
        if (entry.path().filename().string().find(".partial") != std::string::npos) return true;
      return false;
    };
    for (int waited = 0; waited < 6000 && !partial_exists(); ++waited) ::usleep(10000);
    EXPECT_TRUE(partial_exists()) << "the run never started writing";
    ::kill(child, signal_number);
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == signal_number) << "signal " << signal_number;
    EXPECT_FALSE(fs::exists(out));
    EXPECT_FALSE(partial_exists()) << "signal " << signal_number;
  }
}

// Under an address-space limit (common on clusters) the system refuses most of 64 threads: the runs go on
// with those it starts and give one thread's answers, instead of waiting forever for threads that never came
// (issue 34). `timeout` turns a hang into a failure.
TEST_F(Cli, RunsGoOnWithTheThreadsTheSystemStarts) {
  ASSERT_EQ(run("distance @grid:30:30 --source 0 --threads 1 --out " + arg("one.txt")).exit_code, 0);
  ASSERT_EQ(run("matrix @grid:30:30 --sources 0 5 --threads 1 --out " + arg("one.csv")).exit_code, 0);
  const auto limited = [&](const std::string& arguments) {
    const std::string command = "(ulimit -v 307200; timeout 120 '" EXACTGEO_CLI_PATH "' " + arguments + ") >/dev/null 2>" +
                                arg("limited.err");
    const int status = std::system(command.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  };
  EXPECT_EQ(limited("distance @grid:30:30 --source 0 --threads 64 --out " + arg("many.txt")), 0)
      << read_file(path("limited.err"));
  const std::vector<double> many = parse_txt(path("many.txt")), one = parse_txt(path("one.txt"));
  ASSERT_EQ(many.size(), one.size());
  const double largest = *std::max_element(one.begin(), one.end());
  for (std::size_t v = 0; v < one.size(); ++v) EXPECT_NEAR(many[v], one[v], 1e-14 * largest) << "vertex " << v;
  EXPECT_EQ(limited("matrix @grid:30:30 --sources 0 5 --threads 64 --out " + arg("many.csv")), 0)
      << read_file(path("limited.err"));
  EXPECT_EQ(read_file(path("many.csv")), read_file(path("one.csv")));
}

// CLI11 stored a count too large for its variable clamped: 2^64 samples ran as 2^64 - 1 and exited 0.
TEST_F(Cli, CountsTooLargeForTheirVariableAreUsageErrors) {
  const RunResult samples = run("sample @icosphere:1 -k 18446744073709551616");
  expect_error(samples, 1, "--count");
  expect_error(samples, 1, "'18446744073709551616' is not a whole number from 0 to 18446744073709551615");
  expect_error(run("distance @icosphere:1 --source 0 --threads 4294967296"), 1, "--threads");
  expect_error(run("matrix @icosphere:1 --sources 0 --threads 4294967296 --out " + arg("m.npy")), 1, "--threads");
}

// info --json and --stats exited 3: nlohmann::json refuses to write a string that is not UTF-8, as a file name
// may be.
TEST_F(Cli, JsonOutputsTakeFileNamesThatAreNotUtf8) {
  write_file(path("seam-\xff.obj"), kSeamObj);
  const std::string replaced = path("seam-\xef\xbf\xbd.obj").string();  // U+FFFD in place of the byte
  const RunResult info = run("info --json " + arg("seam-\xff.obj"));
  ASSERT_EQ(info.exit_code, 0) << info.err;
  EXPECT_EQ(nlohmann::json::parse(info.out)["mesh"], replaced);
  EXPECT_NE(info.err.find("not UTF-8 has U+FFFD in place of its invalid bytes"), std::string::npos) << info.err;
  const RunResult distance =
      run("distance " + arg("seam-\xff.obj") + " --source 0 --weld --out " + arg("d.txt") + " --stats " + arg("s.json"));
  ASSERT_EQ(distance.exit_code, 0) << distance.err;
  EXPECT_EQ(nlohmann::json::parse(read_file(path("s.json")))["mesh"], replaced);
  EXPECT_NE(distance.err.find("U+FFFD"), std::string::npos) << distance.err;
}

// --out d.csv --target-out d.csv kept one of the two files, without a word.
TEST_F(Cli, OutputsNamingOneFileAreUsageErrors) {
  const std::string run_with = "distance @icosphere:1 --source 0 --targets 3 ";
  expect_error(run(run_with + "--out " + arg("d.csv") + " --target-out " + arg("d.csv")), 1,
               "--out and --target-out both write to");
  expect_error(run(run_with + "--out " + arg("d.csv") + " --stats " + arg("d.csv")), 1, "--out and --stats both write to");
  expect_error(run(run_with + "--target-out " + arg("d.csv") + " --stats '" + (path(".") / "d.csv").string() + "'"), 1,
               "--target-out and --stats both write to");
  fs::create_symlink("d.csv", path("link.csv"));  // to a file not written yet
  expect_error(run(run_with + "--out " + arg("link.csv") + " --stats " + arg("d.csv")), 1, "both write to");
  write_file(path("d.csv"), "kept\n");
  fs::create_hard_link(path("d.csv"), path("hard.csv"));
  expect_error(run(run_with + "--out " + arg("hard.csv") + " --target-out " + arg("d.csv")), 1, "both write to");
  EXPECT_EQ(read_file(path("d.csv")), "kept\n");
  EXPECT_EQ(run(run_with + "--out " + arg("d.csv") + " --target-out " + arg("t.csv")).exit_code, 0);
}

// A FIFO given as --out was replaced by a regular file, and so was a symbolic link, rather than written to.
TEST_F(Cli, OutputsGoIntoFifosAndThroughLinks) {
  ASSERT_EQ(run("distance @icosphere:1 --source 3 --out " + arg("expected.csv")).exit_code, 0);
  const std::string expected = read_file(path("expected.csv"));

  ASSERT_EQ(::mkfifo(path("pipe.csv").c_str(), 0600), 0);
  // The reader gives up after a while: a FIFO that nobody writes to would otherwise hold the test forever.
  const std::string command = "timeout 60 cat " + arg("pipe.csv") + " >" + arg("from-pipe.csv") + " & '" EXACTGEO_CLI_PATH
                              "' distance @icosphere:1 --source 3 --out " + arg("pipe.csv") +
                              " 2>" + arg("err.txt") + "; code=$?; wait; exit $code";
  const int status = std::system(command.c_str());
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << read_file(path("err.txt"));
  EXPECT_TRUE(fs::is_fifo(path("pipe.csv")));
  EXPECT_EQ(read_file(path("from-pipe.csv")), expected);

  fs::create_directory(path("real"));
  fs::create_symlink("real/d.csv", path("link.csv"));  // to a file not written yet
  for (int pass = 0; pass < 2; ++pass) {  // then over the file written the first time
    ASSERT_EQ(run("distance @icosphere:1 --source 3 --out " + arg("link.csv")).exit_code, 0);
    EXPECT_TRUE(fs::is_symlink(path("link.csv"))) << "pass " << pass;
    EXPECT_EQ(read_file(path("real/d.csv")), expected) << "pass " << pass;
  }
}

// --algorithm ftp --threads 4 reported 4 threads, in the summary and --stats, while it ran on one.
TEST_F(Cli, SummaryAndStatsGiveTheThreadsTheRunShared) {
  const RunResult ftp =
      run("distance @icosphere:2 --source 0 --quiet --algorithm ftp --threads 4 --stats " + arg("f.json"));
  ASSERT_EQ(ftp.exit_code, 0) << ftp.err;
  EXPECT_EQ(nlohmann::json::parse(read_file(path("f.json")))["threads"], 1);
  // The summary's row: the name, spaces to align the values, the value.
  std::istringstream summary(ftp.out);
  std::string row;
  while (std::getline(summary, row) && !row.starts_with("threads ")) {
  }
  ASSERT_TRUE(row.starts_with("threads ")) << ftp.out;
  EXPECT_EQ(row.substr(row.find_first_not_of(' ', std::string_view("threads").size())), "1") << ftp.out;
  EXPECT_NE(ftp.err.find("note: the run used 1 of the 4 threads asked for: the face-sorted variants"), std::string::npos)
      << ftp.err;

  const RunResult vtp = run("distance @icosphere:2 --source 0 --quiet --threads 2 --stats " + arg("v.json"));
  ASSERT_EQ(vtp.exit_code, 0) << vtp.err;
  EXPECT_EQ(nlohmann::json::parse(read_file(path("v.json")))["threads"], 2);
  EXPECT_EQ(vtp.err, "");
}

}  // namespace
