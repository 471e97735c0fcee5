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
  endif()
endfunction()
