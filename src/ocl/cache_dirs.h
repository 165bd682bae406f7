// Where the on-disk caches live when nobody has said: the engine's program cache
// (resolve_cache_dir) and PoCL's kernel cache. Both belong in the user's cache directory
// ($XDG_CACHE_HOME, else $HOME/.cache); a service user with no home, or a home that cannot be
// written, gets a private directory under the system temp directory instead. Internal to
// src/ocl; README.md, "Cache directories", says what a user sees.
#pragma once
#include <filesystem>
#include <string>

namespace planarvo::ocl::detail {

// Whether dir can hold a cache: it is a directory this process can write, or it does not exist
// and its nearest existing ancestor is one (so it can be created). Has no side effects.
bool cache_dir_usable(const std::filesystem::path& dir);

// $XDG_CACHE_HOME/<app> when XDG_CACHE_HOME is set and not empty, else $HOME/.cache/<app> when
// HOME is; empty when neither is.
std::filesystem::path user_cache_dir(const std::string& app);

// <temp>/planarvo-<uid>, where <temp> is the system temp directory ($TMPDIR, else /tmp) and
// <uid> the effective user id: a directory for caches that only this user can write, created
// with mode 0700 when missing. Empty when it cannot be created, or when what is there is not a
// directory (a symlink is not) owned by this user and writable by no one else, since another
// user could then plant binaries in it.
std::filesystem::path private_temp_dir();

// Whether the driver keeps the kernels it compiles in a persistent cache of its own, keyed by the
// program's source and build options, so that a later run does not compile them again: PoCL
// (its kcache), unless POCL_KERNEL_CACHE=0 turns that off. The engine's program cache is then off
// unless a directory was chosen (RuntimeOptions::cache_dir, PLANARVO_CACHE_DIR): it would add
// nothing to the driver's, and writing an entry costs PoCL a compile of every kernel of the
// program for a generic work-group size (CL_PROGRAM_BINARIES), measured at about 5 s over the
// tracker's and the calibration's programs on a first run.
bool driver_caches_kernels(const std::string& platform_name);

// Called before the first OpenCL platform query. When POCL_CACHE_DIR is not set and the
// directory PoCL would otherwise use is not usable, sets POCL_CACHE_DIR to
// private_temp_dir()/pocl. (PoCL 3.1 fails to initialise its device when it cannot create its
// cache directory, even with POCL_KERNEL_CACHE=0: with HOME unset it uses /tmp/pocl, which the
// first user to run it owns with mode 0700, so every other user finds no device; with a HOME
// it cannot write, such as /nonexistent, it finds none either.) Does its work once per process;
// returns "" when PoCL has a usable cache directory, else a sentence saying that it has none
// and what to do, for the message of a failed device search.
const std::string& prepare_driver_environment();

}  // namespace planarvo::ocl::detail
