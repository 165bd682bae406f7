// The manifest of a prebuilt-binaries directory: which file holds which program, built with
// which options, for which device, and what its bytes are. Internal to src/ocl; README.md
// repeats the format for users.
//
// <dir>/planarvo-kernels.txt is UTF-8 text. Lines that are blank or whose first non-blank
// character is '#' are comments. Every other line describes one binary in 5 to 9 fields
// separated by TAB characters (spaces around a field are ignored):
//
//   program  options-hash  file  device  driver  [options  [for  [size  sha256]]]
//
//   program       the program's name: kernels/<program>.cl, e.g. "fill"
//   options-hash  FNV-1a 64 of the normalised options, as 16 lowercase hex digits; "-" skips
//                 the check (convenient for hand-written lines)
//   file          the binary's file, relative to the directory (or absolute); several lines
//                 may name the same file (e.g. one Intel FPGA .aocx holding every kernel)
//   device        CL_DEVICE_NAME as `planarvo devices` prints it, or "*" for any device
//   driver        CL_DRIVER_VERSION, or "*" for any driver version
//   options       the build options as given to Runtime::program(), normalised
//                 (normalize_build_options): trimmed, whitespace runs outside double quotes
//                 turned into one space; an absent sixth field means "" (no options)
//   for           what needs the binary: the uses it is registered for
//                 (Runtime::register_build_options), comma-separated, e.g. "calibrate,track";
//                 absent or empty when unknown. Informative only: lookups never read it.
//                 Manifests of format 1 (before this field) have 5 or 6 fields and stay valid;
//                 a line with this field and no options has an empty sixth field.
//   size, sha256  the file's size in bytes and its SHA-256 (64 lowercase hex digits), written
//                 by export since format 3; "-" (or absent) skips the check. A file that does
//                 not match is refused before the driver sees it: a truncated, swapped or
//                 corrupted binary crashed or silently misled drivers (issue 27).
//
// A program is looked up by (program, normalised options); among its lines, the first whose
// device and driver match the running device is used. Lines for other devices may share one
// directory. Fields cannot contain TABs or line breaks; Windows line ends are accepted.
#pragma once
#include <string>
#include <vector>

namespace planarvo::ocl::detail {

struct ManifestEntry {
  std::string program;
  std::string options_hash;  // 16 hex digits or "-"
  std::string file;
  std::string device;        // or "*"
  std::string driver;        // or "*"
  std::string options;       // normalised
  std::string uses;          // the "for" field: comma-separated uses, "" when unknown
  long long size = -1;       // bytes; -1: not recorded
  std::string sha256;        // 64 hex digits; "": not recorded
  int line = 0;              // 1-based line in the manifest, for messages
};

// Throws Error(InvalidInput) naming path and line for a malformed line (wrong field count,
// empty program or file, an options hash that does not match the options).
std::vector<ManifestEntry> parse_manifest(const std::string& text, const std::string& path);

// The text export_binaries() writes: a comment header documenting the format, then one line
// per entry.
std::string format_manifest(const std::vector<ManifestEntry>& entries);

// The options hash the manifest stores for (already normalised) options.
std::string options_hash(const std::string& normalized_options);

}  // namespace planarvo::ocl::detail
