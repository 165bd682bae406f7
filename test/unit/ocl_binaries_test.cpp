// Prebuilt program binaries (the FPGA path): export, manifest, loading without a compiler, and
// the errors a user sees when the directory does not fit (src/ocl/manifest.h).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "common/test_util.h"
#include "core/error.h"
#include "core/sha256.h"
#include "core/tasks.h"
#include "ocl/manifest.h"
#include "ocl/runtime.h"
#include "unit/ocl_test_helpers.h"

namespace planarvo {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void write_text(const fs::path& p, const std::string& s) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out << s;
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::string cur;
  std::istringstream in(s);
  while (std::getline(in, cur, sep)) out.push_back(cur);
  return out;
}

// The manifest's non-comment lines, split into fields.
std::vector<std::vector<std::string>> all_manifest_lines(const fs::path& dir) {
  std::vector<std::vector<std::string>> out;
  for (const std::string& line : split(read_text(dir / ocl::kManifestFileName), '\n'))
    if (!line.empty() && line[0] != '#') out.push_back(split(line, '\t'));
  return out;
}

// Those of the test program `fill` with the fixture's variants, "" and "-D VARIANT=7" (the
// engine's other programs are exported too, and other tests register other variants of fill:
// none of these tests' business).
std::vector<std::vector<std::string>> manifest_lines(const fs::path& dir) {
  std::vector<std::vector<std::string>> out;
  for (auto& fields : all_manifest_lines(dir)) {
    const std::string options = fields.size() > 5 ? fields[5] : std::string();
    if (fields[0] == "fill" && (options.empty() || options == "-D VARIANT=7"))
      out.push_back(std::move(fields));
  }
  return out;
}

ocl::RuntimeOptions from_binaries(const fs::path& dir) {
  ocl::RuntimeOptions o;
  o.binaries_dir = dir.string();
  o.use_cache = false;
  return o;
}

// Exports every program with fill's "" and "-D VARIANT=7" variants into dir.
void export_to(const fs::path& dir) {
  ocl::Runtime::register_build_options("fill", "");
  ocl::Runtime::register_build_options("fill", "-D VARIANT=7");
  ocl::RuntimeOptions o;
  o.use_cache = false;
  ocl::Runtime rt(o);
  rt.export_binaries(dir.string());
}

class OclBinaries : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = scratch_ / "binaries";
    export_to(dir_);
  }
  // The manifest line for fill with the given options.
  std::vector<std::string> fill_line(const std::string& options) {
    for (const auto& f : manifest_lines(dir_))
      if (f[0] == "fill" && (f.size() > 5 ? f[5] : std::string()) == options) return f;
    ADD_FAILURE() << "no manifest line for fill with \"" << options << "\"";
    return {};
  }
  test::ScratchDir scratch_;
  fs::path dir_;
};

TEST_F(OclBinaries, ExportWritesABinaryAndAManifestLinePerVariant) {
  ocl::Runtime rt;
  const auto lines = manifest_lines(dir_);
  ASSERT_EQ(lines.size(), 2u);  // fill twice; the prelude (if any) is never a program
  for (const auto& f : lines) {
    ASSERT_GE(f.size(), 5u);
    EXPECT_EQ(f[0], "fill");
    EXPECT_EQ(f[1].size(), 16u);  // options hash
    EXPECT_TRUE(fs::is_regular_file(dir_ / f[2])) << f[2];
    EXPECT_GT(fs::file_size(dir_ / f[2]), 0u);
    EXPECT_EQ(f[3], rt.device_info().device_name);
    EXPECT_EQ(f[4], rt.device_info().driver_version);
  }
  EXPECT_NE(fill_line("")[2], fill_line("-D VARIANT=7")[2]);
  // The documented hash: FNV-1a 64 of the options, 16 lowercase hex digits.
  char hash[17];
  std::snprintf(hash, sizeof hash, "%016llx",
                static_cast<unsigned long long>(ocl::fnv1a64("-D VARIANT=7")));
  EXPECT_EQ(fill_line("-D VARIANT=7")[1], hash);
  EXPECT_EQ(ocl::fnv1a64(""), 0xcbf29ce484222325ull);  // FNV-1a 64's offset basis
  EXPECT_EQ(ocl::fnv1a64("a"), 0xaf63dc4c8601ec8cull);  // the published test vector
}

TEST_F(OclBinaries, RuntimeRunsFromBinariesWithoutCompiling) {
  ocl::Runtime rt(from_binaries(dir_));
  test::expect_fill_works(rt, rt.program("fill"));
  test::expect_fill_works(rt, rt.program("fill", "  -D VARIANT=7 "));
  EXPECT_EQ(rt.stats().built_from_source, 0);
  EXPECT_EQ(rt.stats().loaded_from_cache, 0);
  EXPECT_EQ(rt.stats().loaded_from_binaries, 2);
}

TEST_F(OclBinaries, MissingManifestNamesProgramDeviceAndDirectory) {
  fs::remove(dir_ / ocl::kManifestFileName);
  ocl::Runtime rt(from_binaries(dir_));
  const std::string msg =
      test::error_message([&] { rt.program("fill"); }, ErrorCode::InvalidInput);
  EXPECT_THAT(msg, HasSubstr("\"fill\""));
  EXPECT_THAT(msg, HasSubstr(rt.device_info().device_name));
  EXPECT_THAT(msg, HasSubstr(dir_.string()));
  EXPECT_THAT(msg, HasSubstr(ocl::kManifestFileName));
}

TEST_F(OclBinaries, MissingBinaryFileNamesProgramDeviceAndDirectory) {
  const auto line = fill_line("-D VARIANT=7");
  ASSERT_FALSE(line.empty());
  fs::remove(dir_ / line[2]);
  ocl::Runtime rt(from_binaries(dir_));
  EXPECT_NO_THROW(rt.program("fill"));  // the other variant is still there
  const std::string msg = test::error_message([&] { rt.program("fill", "-D VARIANT=7"); },
                                              ErrorCode::InvalidInput);
  EXPECT_THAT(msg, HasSubstr("\"fill\""));
  EXPECT_THAT(msg, HasSubstr("-D VARIANT=7"));
  EXPECT_THAT(msg, HasSubstr(line[2]));
  EXPECT_THAT(msg, HasSubstr("missing"));
  EXPECT_THAT(msg, HasSubstr(rt.device_info().device_name));
  EXPECT_THAT(msg, HasSubstr(dir_.string()));
}

TEST_F(OclBinaries, BinaryForAnotherDeviceIsMismatched) {
  std::string text = read_text(dir_ / ocl::kManifestFileName);
  ocl::Runtime probe;
  const std::string& name = probe.device_info().device_name;
  for (size_t at = text.find('\t' + name + '\t'); at != std::string::npos;
       at = text.find('\t' + name + '\t'))
    text.replace(at + 1, name.size(), "Some Other FPGA Board");
  write_text(dir_ / ocl::kManifestFileName, text);

  ocl::Runtime rt(from_binaries(dir_));
  const std::string msg =
      test::error_message([&] { rt.program("fill"); }, ErrorCode::InvalidInput);
  EXPECT_THAT(msg, HasSubstr("mismatched binary"));
  EXPECT_THAT(msg, HasSubstr("built for \"Some Other FPGA Board\""));
  EXPECT_THAT(msg, HasSubstr("this device is \"" + name + "\""));
  EXPECT_THAT(msg, HasSubstr("fill"));
  EXPECT_THAT(msg, HasSubstr(dir_.string()));
}

TEST_F(OclBinaries, BinaryForAnotherDriverIsMismatched) {
  const auto line = fill_line("");
  ASSERT_GE(line.size(), 5u);
  std::string text = read_text(dir_ / ocl::kManifestFileName);
  const char end = line.size() > 5 ? '\t' : '\n';
  const std::string old_fields = '\t' + line[3] + '\t' + line[4] + end;
  const size_t at = text.find(line[2] + old_fields);
  ASSERT_NE(at, std::string::npos);
  text.replace(at + line[2].size(), old_fields.size(), '\t' + line[3] + "\t0.0-older" + end);
  write_text(dir_ / ocl::kManifestFileName, text);

  ocl::Runtime rt(from_binaries(dir_));
  const std::string msg =
      test::error_message([&] { rt.program("fill"); }, ErrorCode::InvalidInput);
  EXPECT_THAT(msg, HasSubstr("mismatched binary"));
  EXPECT_THAT(msg, HasSubstr("driver 0.0-older"));
  EXPECT_THAT(msg, HasSubstr(rt.device_info().driver_version));
}

TEST_F(OclBinaries, VariantNotExportedIsNamed) {
  ocl::Runtime rt(from_binaries(dir_));
  const std::string msg = test::error_message([&] { rt.program("fill", "-D VARIANT=8"); },
                                              ErrorCode::InvalidInput);
  EXPECT_THAT(msg, HasSubstr("no prebuilt binary"));
  EXPECT_THAT(msg, HasSubstr("\"fill\" with options \"-D VARIANT=8\""));
  EXPECT_THAT(msg, HasSubstr("\"-D VARIANT=7\""));  // what there is instead
  EXPECT_THAT(msg, HasSubstr(rt.device_info().device_name));
  EXPECT_THAT(msg, HasSubstr(dir_.string()));
  EXPECT_EQ(rt.stats().built_from_source, 0);  // no fallback to the compiler
}

// Garbage under a manifest line that checks neither size nor hash (a hand-written one): the
// driver's refusal. With the exported line's size and SHA-256 the file never reaches the driver
// (KernelBinaries.DamagedBinariesAreExit2NamingTheFileBeforeTheDriverSeesThem).
TEST_F(OclBinaries, DriverRejectingTheBinaryIsAnOpenCLError) {
  const auto line = fill_line("");
  ASSERT_EQ(line.size(), 9u);
  write_text(dir_ / line[2], std::string(4096, '\x7f'));
  {
    ocl::Runtime checked(from_binaries(dir_));
    const std::string msg = test::error_message([&] { checked.program("fill"); }, ErrorCode::InvalidInput);
    EXPECT_THAT(msg, HasSubstr("4096 bytes, the manifest says " + line[7]));
  }
  std::string text = read_text(dir_ / ocl::kManifestFileName);
  const std::string checks = '\t' + line[7] + '\t' + line[8];
  const size_t at = text.find(line[2] + '\t' + line[3] + '\t' + line[4]);
  ASSERT_NE(at, std::string::npos);
  text.replace(text.find(checks, at), checks.size(), "\t-\t-");
  write_text(dir_ / ocl::kManifestFileName, text);
  ocl::Runtime rt(from_binaries(dir_));
  const std::string msg = test::error_message([&] { rt.program("fill"); }, ErrorCode::OpenCL);
  EXPECT_THAT(msg, HasSubstr("\"fill\""));
  EXPECT_THAT(msg, HasSubstr(line[2]));
  EXPECT_THAT(msg, HasSubstr(rt.device_info().device_name));
  EXPECT_THAT(msg, HasSubstr(dir_.string()));
}

TEST_F(OclBinaries, HandWrittenLineLoadsAVendorBinary) {
  // What an FPGA user does with an .aocx: copy the file in, write one line by hand, with "-"
  // for the hash, "*" for the driver and no options field.
  const auto line = fill_line("");
  ASSERT_FALSE(line.empty());
  const fs::path vendor = scratch_ / "vendor";
  fs::create_directories(vendor / "board");
  fs::copy_file(dir_ / line[2], vendor / "board" / "kernels.aocx");
  ocl::Runtime probe;
  write_text(vendor / ocl::kManifestFileName,
             "# written by hand\n\n"
             "fill \t - \t board/kernels.aocx \t " + probe.device_info().device_name +
                 " \t *\r\n");
  ocl::Runtime rt(from_binaries(vendor));
  test::expect_fill_works(rt, rt.program("fill"));
  EXPECT_EQ(rt.stats().loaded_from_binaries, 1);
}

TEST_F(OclBinaries, MalformedManifestNamesTheLine) {
  write_text(dir_ / ocl::kManifestFileName, "# comment\nfill only-two-fields\n");
  ocl::Runtime rt(from_binaries(dir_));
  const std::string msg =
      test::error_message([&] { rt.program("fill"); }, ErrorCode::InvalidInput);
  EXPECT_THAT(msg, HasSubstr(std::string(ocl::kManifestFileName) + ":2"));
  EXPECT_THAT(msg, HasSubstr("TAB"));

  write_text(dir_ / ocl::kManifestFileName, "fill\t0123456789abcdef\tx.bin\t*\t*\t-D A=1\n");
  const std::string bad_hash =
      test::error_message([&] { rt.program("fill"); }, ErrorCode::InvalidInput);
  EXPECT_THAT(bad_hash, HasSubstr("options hash 0123456789abcdef does not match"));
}

TEST_F(OclBinaries, ReExportKeepsOtherDevicesAndReplacesThisOne) {
  const std::string foreign = "fill\t-\tother.bin\tSome Other FPGA Board\t1.0\n";
  write_text(dir_ / ocl::kManifestFileName,
             read_text(dir_ / ocl::kManifestFileName) + foreign);
  export_to(dir_);
  const auto lines = manifest_lines(dir_);
  EXPECT_EQ(lines.size(), 3u);
  EXPECT_THAT(read_text(dir_ / ocl::kManifestFileName), HasSubstr(foreign));
}

// The uses a variant is registered for narrow the export (`planarvo kernels --for`), reach the
// manifest's seventh field, and name what to export when a variant is missing.
TEST(OclBinariesExport, ForAUseWritesOnlyItsVariantsAndSaysWhatTheyAreFor) {
  ocl::Runtime::register_build_options("fill", "-D VARIANT=21", {"fill-use-a"});
  ocl::Runtime::register_build_options("fill", "-D VARIANT=22", {"fill-use-a", "fill-use-b"});
  ocl::Runtime::register_build_options("fill", "-D VARIANT=23", {"fill-use-b"});
  ocl::Runtime::register_build_options("fill", "-D VARIANT=23");  // adds no use, removes none
  EXPECT_EQ(ocl::Runtime::registered_uses("fill", " -D  VARIANT=22"),
            (std::vector<std::string>{"fill-use-a", "fill-use-b"}));
  EXPECT_EQ(ocl::Runtime::registered_uses("fill", "-D VARIANT=23"),
            (std::vector<std::string>{"fill-use-b"}));
  const std::vector<std::string> known = ocl::Runtime::known_uses();
  for (const char* u : {"fill-use-a", "fill-use-b", tasks::kTrack, tasks::kCalibrate, tasks::kSimulate})
    EXPECT_NE(std::find(known.begin(), known.end(), u), known.end()) << u;

  test::ScratchDir scratch;
  const fs::path dir = scratch / "for-a";
  ocl::RuntimeOptions o;
  o.use_cache = false;
  ocl::Runtime rt(o);
  EXPECT_EQ(rt.export_binaries(dir.string(), {"fill-use-a"}), 2u);
  const auto lines = all_manifest_lines(dir);
  ASSERT_EQ(lines.size(), 2u);  // VARIANT=21 and 22; nothing of the engine's own programs
  std::map<std::string, std::string> for_field;
  for (const auto& f : lines) {
    ASSERT_EQ(f.size(), 9u);  // ... for, size, sha256
    EXPECT_EQ(f[0], "fill");
    for_field[f[5]] = f[6];
  }
  EXPECT_EQ(for_field["-D VARIANT=21"], "fill-use-a");
  EXPECT_EQ(for_field["-D VARIANT=22"], "fill-use-a,fill-use-b");

  // The binaries load; a variant of another use is missing, and the message says which command
  // needs it and how to export it, without C++ names.
  ocl::Runtime from(from_binaries(dir));
  test::expect_fill_works(from, from.program("fill", "-D VARIANT=22"));
  const std::string msg = test::error_message([&] { from.program("fill", "-D VARIANT=23"); },
                                              ErrorCode::InvalidInput);
  EXPECT_THAT(msg, HasSubstr("\"fill\" with options \"-D VARIANT=23\""));
  EXPECT_THAT(msg, HasSubstr("never compiles"));
  EXPECT_THAT(msg, HasSubstr("The command fill-use-b uses it"));
  EXPECT_THAT(msg, HasSubstr("`planarvo kernels --export " + dir.string() + " --for fill-use-b`"));
  EXPECT_THAT(msg, ::testing::Not(HasSubstr("::")));
  EXPECT_EQ(from.stats().built_from_source, 0);

  const std::string unknown = test::error_message(
      [&] { rt.export_binaries((scratch / "x").string(), {"no-such-use"}); }, ErrorCode::InvalidArgument);
  EXPECT_THAT(unknown, HasSubstr("\"no-such-use\""));
  EXPECT_THAT(unknown, HasSubstr(tasks::kTrack));
}

TEST(OclManifest, ReadsFormat1And2Lines) {
  const std::string text =
      "# format 1: 5 or 6 fields\n"
      "fill\t-\ta.bin\t*\t*\n"
      "fill\t-\tb.bin\t*\t*\t-D VARIANT=7\n"
      "fill\t-\tc.bin\t*\t*\t\n"
      "# format 2: a seventh field says what the binary is for\n"
      "fill\t-\td.bin\t*\t*\t-D VARIANT=7\tcalibrate,track\n"
      "fill\t-\te.bin\t*\t*\t\tsimulate\r\n"
      "fill\t-\tf.bin\t*\t*\t\t\n";
  const auto e = ocl::detail::parse_manifest(text, "m.txt");
  ASSERT_EQ(e.size(), 6u);
  const std::vector<std::pair<std::string, std::string>> want = {
      {"", ""}, {"-D VARIANT=7", ""}, {"", ""}, {"-D VARIANT=7", "calibrate,track"}, {"", "simulate"}, {"", ""}};
  for (size_t i = 0; i < e.size(); ++i) {
    EXPECT_EQ(e[i].options, want[i].first) << i;
    EXPECT_EQ(e[i].uses, want[i].second) << i;
  }
  // Written back, a line keeps its field, and one without says nothing more than format 1 did.
  const std::string out = ocl::detail::format_manifest(e);
  EXPECT_THAT(out, HasSubstr("fill\t-\ta.bin\t*\t*\n"));
  EXPECT_THAT(out, HasSubstr("fill\t-\td.bin\t*\t*\t-D VARIANT=7\tcalibrate,track\n"));
  EXPECT_THAT(out, HasSubstr("fill\t-\te.bin\t*\t*\t\tsimulate\n"));
  EXPECT_EQ(ocl::detail::parse_manifest(out, "m.txt").size(), 6u);

  const std::string eight = test::error_message(
      [&] { ocl::detail::parse_manifest("fill\t-\ta.bin\t*\t*\t\tx\ty\n", "m.txt"); },
      ErrorCode::InvalidInput);
  EXPECT_THAT(eight, HasSubstr("m.txt:1"));
  EXPECT_THAT(eight, HasSubstr("found 8"));
}

// Format 3: each binary's size and SHA-256, checked before the driver sees the file.
TEST(OclManifest, ReadsAndChecksFormat3SizeAndHash) {
  const std::string hash(64, 'a');
  const std::string text = "fill\t-\ta.bin\t*\t*\t\t\t1234\t" + hash + "\n" +
                           "fill\t-\tb.bin\t*\t*\t-D VARIANT=7\ttrack\t-\t-\n";
  const auto e = ocl::detail::parse_manifest(text, "m.txt");
  ASSERT_EQ(e.size(), 2u);
  EXPECT_EQ(e[0].size, 1234);
  EXPECT_EQ(e[0].sha256, hash);
  EXPECT_EQ(e[1].size, -1);
  EXPECT_EQ(e[1].sha256, "");
  EXPECT_EQ(e[1].uses, "track");
  const auto back = ocl::detail::parse_manifest(ocl::detail::format_manifest(e), "m.txt");
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[0].size, 1234);
  EXPECT_EQ(back[0].sha256, hash);
  for (const char* bad : {"fill\t-\ta.bin\t*\t*\t\t\t12x\t-\n", "fill\t-\ta.bin\t*\t*\t\t\t-\tABC\n",
                                 "fill\t-\ta.bin\t*\t*\t\t\t-1\t-\n"}) {
    const std::string msg = test::error_message([&] { ocl::detail::parse_manifest(bad, "m.txt"); },
                                                ErrorCode::InvalidInput);
    EXPECT_THAT(msg, HasSubstr("m.txt:1")) << bad;
  }
}

// Against FIPS 180-4's examples (and the million-'a' vector of its test suite).
TEST(Sha256, MatchesThePublishedVectors) {
  EXPECT_EQ(sha256_hex("", 0), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256_hex("abc", 3), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  const std::string two_blocks = "abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq";
  EXPECT_EQ(sha256_hex(two_blocks.data(), two_blocks.size()),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  const std::string million(1000000, 'a');
  EXPECT_EQ(sha256_hex(million.data(), million.size()),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
  // Lengths around the padding's block boundaries, against coreutils' sha256sum.
  const std::map<size_t, std::string> sums = {
      {55, "9f4390f8d30c2dd92ec9f095b65e2b9ae9b0a925a5258e241c9f1e910f734318"},
      {56, "b35439a4ac6f0948b6d6f9e3c6af0f5f590ce20f1bde7090ef7970686ec6738a"},
      {63, "7d3e74a05d7db15bce4ad9ec0658ea98e3f06eeecf16b4c6fff2da457ddc2f34"},
      {64, "ffe054fe7ae0cb6dc65c3af9b61d5209f439851db43d0ba5997337df154668eb"},
      {65, "635361c48bb9eab14198e76ea8ab7f1a41685d6ad62aa9146d301d4f17eb0ae0"},
      {119, "31eba51c313a5c08226adf18d4a359cfdfd8d2e816b13f4af952f7ea6584dcfb"},
      {120, "2f3d335432c70b580af0e8e1b3674a7c020d683aa5f73aaaedfdc55af904c21c"}};
  for (const auto& [n, sum] : sums) EXPECT_EQ(sha256_hex(million.data(), n), sum) << n << " bytes";
}

TEST(OclBinariesExport, UnwritableDirectoryIsAnIoError) {
  test::ScratchDir scratch;
  write_text(scratch / "file", "x");
  ocl::Runtime rt;
  const std::string dir = (scratch / "file" / "binaries").string();
  const std::string msg =
      test::error_message([&] { rt.export_binaries(dir); }, ErrorCode::Io);
  EXPECT_THAT(msg, HasSubstr(dir));
}

}  // namespace
}  // namespace planarvo
