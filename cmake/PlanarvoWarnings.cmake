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
  # -O1 (after the build type's -O3, so it wins): GCC 12 spent 40 CPU-minutes on the instrumented
  # -O3 build, 2.8 times the plain one (a graph test file: 39 s at -O3, 23 s at -O1), while the
  # suite's time is mostly OpenCL kernels, which PoCL compiles without the sanitizers.
  add_compile_options(-O1)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
endif()
if(PLANARVO_TSAN)
  add_compile_options(-fsanitize=thread -fno-omit-frame-pointer)
  add_link_options(-fsanitize=thread)
endif()
