# Warnings for the project's own targets (not for third-party headers, which
# come in as SYSTEM include directories through their imported targets).
function(articula_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor)
endfunction()
