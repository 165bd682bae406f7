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
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
endif()
if(PLANARVO_TSAN)
  add_compile_options(-fsanitize=thread -fno-omit-frame-pointer)
  add_link_options(-fsanitize=thread)
endif()
