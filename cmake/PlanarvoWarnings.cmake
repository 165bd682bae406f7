# Compiler warnings and sanitizers for planarvo's own targets.
function(planarvo_set_warnings target)
  if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    target_compile_options(${target} PRIVATE
      -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Woverloaded-virtual
      -Wcast-align -Wformat=2 -Wmissing-declarations -Wimplicit-fallthrough)
    if(PLANARVO_WERROR)
      target_compile_options(${target} PRIVATE -Werror)
    endif()
  endif()
endfunction()

if(PLANARVO_SANITIZE AND PLANARVO_TSAN)
  message(FATAL_ERROR "PLANARVO_SANITIZE (ASan + UBSan) and PLANARVO_TSAN exclude each other: use two build folders")
endif()
if(PLANARVO_SANITIZE)
  # After the build type's -O3, so it wins. GCC: -O1; GCC 12 spent 40 CPU-minutes on the
  # instrumented -O3 build, 2.8 times the plain one (a graph test file: 39 s at -O3, 23 s at
  # -O1), while the suite's time is mostly OpenCL kernels, which PoCL compiles without the
  # sanitizers. clang (scripts/test.sh): -O2, which compiles as fast as its -O1 (tracker.cpp:
  # 36 s, against GCC's 50 s at -O1) and inlines Eigen, which its -O1 does not (the suite took
  # twice GCC's time).
  if(CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    add_compile_options(-O2)
  else()
    add_compile_options(-O1)
  endif()
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  if(CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    # UBSan's object-size check kept clang from inlining Eigen's small fixed-size matrices (100
    # out-of-line Eigen functions in core/camera.cpp, 39 without it; the suite ran 1.5 times
    # slower); AddressSanitizer checks every access against its object's bounds anyway.
    add_compile_options(-fno-sanitize=object-size)
  endif()
  add_link_options(-fsanitize=address,undefined)
  if(CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    # clang links its runtime statically into executables only; the shared libraries (linked
    # with --no-undefined) and Python need the shared runtime, so every binary takes that one.
    execute_process(COMMAND ${CMAKE_CXX_COMPILER} -print-file-name=libclang_rt.asan-x86_64.so
                    OUTPUT_VARIABLE PLANARVO_CLANG_ASAN_RUNTIME OUTPUT_STRIP_TRAILING_WHITESPACE)
    get_filename_component(PLANARVO_CLANG_ASAN_RUNTIME_DIR "${PLANARVO_CLANG_ASAN_RUNTIME}" DIRECTORY)
    add_link_options(-shared-libsan "LINKER:-rpath,${PLANARVO_CLANG_ASAN_RUNTIME_DIR}")
  endif()
endif()
if(PLANARVO_TSAN)
  add_compile_options(-fsanitize=thread -fno-omit-frame-pointer)
  add_link_options(-fsanitize=thread)
endif()
