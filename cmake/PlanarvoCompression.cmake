# zstd, LZ4 (frame format) and bzip2, for compressed chunks of ROS 1 bags (bz2, lz4) and MCAP
# files (zstd, lz4). Debian 12: libzstd-dev, liblz4-dev, libbz2-dev (scripts/install-deps.sh).
# Sets PLANARVO_COMPRESSION_LIBS and PLANARVO_COMPRESSION_DEFINITIONS (PLANARVO_HAVE_ZSTD=1, ...).
set(PLANARVO_COMPRESSION_LIBS "")
set(PLANARVO_COMPRESSION_DEFINITIONS "")
foreach(entry "ZSTD;zstd;zstd.h" "LZ4;lz4;lz4frame.h" "BZ2;bz2;bzlib.h")
  list(GET entry 0 LIB)
  list(GET entry 1 lib)
  list(GET entry 2 header)
  find_path(PLANARVO_${LIB}_INCLUDE_DIR NAMES ${header})
  find_library(PLANARVO_${LIB}_LIBRARY NAMES ${lib})
  if(PLANARVO_${LIB}_INCLUDE_DIR AND PLANARVO_${LIB}_LIBRARY)
    list(APPEND PLANARVO_COMPRESSION_LIBS ${PLANARVO_${LIB}_LIBRARY})
    list(APPEND PLANARVO_COMPRESSION_DEFINITIONS PLANARVO_HAVE_${LIB}=1)
  else()
    message(STATUS "planarvo: ${lib} not found (Debian: lib${lib}-dev): bags whose chunks are "
                   "compressed with it cannot be read")
    list(APPEND PLANARVO_COMPRESSION_DEFINITIONS PLANARVO_HAVE_${LIB}=0)
  endif()
endforeach()
