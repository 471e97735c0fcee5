# SPDX-License-Identifier: BSD-3-Clause
# Copyright (c) 2026 the kiseki authors
# Compiler options for kiseki's own targets: warnings (errors by default) and sanitizers.
function(kiseki_compile_options target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic)
  if(KISEKI_WARNINGS_AS_ERRORS)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
  if(KISEKI_SANITIZE)
    target_compile_options(${target} PUBLIC -fsanitize=address,undefined -fno-omit-frame-pointer
                                            -fno-sanitize-recover=all)
    target_link_options(${target} PUBLIC -fsanitize=address,undefined)
    # Under ASan, Eigen stops trusting glibc's 16-byte aligned malloc and allocates with an
    # offset of its own; an Eigen vector made by kiseki's code and freed inside Debian's
    # (uninstrumented) PCL is then a bad free (measured in RandomSampleConsensus). glibc's and
    # ASan's malloc both align to 16 bytes, so tell Eigen so, as it assumes without ASan.
    target_compile_definitions(${target} PUBLIC EIGEN_MALLOC_ALREADY_ALIGNED=1)
  endif()
endfunction()
