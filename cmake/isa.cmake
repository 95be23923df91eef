# Per-instruction-set sources, the one way the project enables an instruction set. Code
# for one ISA lives in files named *_avx2.cpp, *_avx512.cpp or *_neon.cpp (kernels/,
# slicing/row_kernels_*, render/composite_*, bench/fma_loop_*); only those files get that
# ISA's compiler flags, so the rest of the program stays portable and dispatch picks a
# variant at run time. No source turns an ISA on by itself (no target pragma or
# attribute), so what may run where can be read from the file names.
#
# The flags apply to everything such a file compiles, inline functions of the headers it
# includes too: an inline or template function shared with other files (a std:: algorithm,
# a container's method) that the compiler leaves out of line there is emitted with the
# ISA's instructions, and the linker may keep that copy for the whole program. So per-ISA
# files use intrinsics, helpers in their own ISA's namespace, and only std:: functions
# small enough to be inlined everywhere (std::min, std::max): their objects' weak symbols
# (`nm -C`) all belong to their own ISA's namespace.

if(CMAKE_SYSTEM_PROCESSOR MATCHES "^(x86_64|AMD64|amd64)$")
  set(AMPI_ARCH_X86 ON)
elseif(CMAKE_SYSTEM_PROCESSOR MATCHES "^(aarch64|arm64)$")
  set(AMPI_ARCH_ARM64 ON)
endif()

# Drop the sources of instruction sets this target architecture cannot run.
function(ampi_filter_isa_sources var)
  set(kept)
  foreach(src IN LISTS ${var})
    if(src MATCHES "_(avx2|avx512)\\.cpp$" AND NOT AMPI_ARCH_X86)
      continue()
    endif()
    if(src MATCHES "_neon\\.cpp$" AND NOT AMPI_ARCH_ARM64)
      continue()
    endif()
    list(APPEND kept ${src})
  endforeach()
  set(${var} ${kept} PARENT_SCOPE)
endfunction()

function(ampi_set_isa_flags target)
  get_target_property(srcs ${target} SOURCES)
  foreach(src IN LISTS srcs)
    if(src MATCHES "_avx2\\.cpp$")
      set_source_files_properties(${src} PROPERTIES COMPILE_OPTIONS "-mavx2;-mfma;-mf16c")
    elseif(src MATCHES "_avx512\\.cpp$")
      set_source_files_properties(${src} PROPERTIES
        # GCC 12 warns falsely inside its own masked-load intrinsics.
        COMPILE_OPTIONS "-mavx512f;-mavx512bw;-mavx512vl;-mavx512dq;-mfma;-mf16c;-Wno-maybe-uninitialized")
    endif()
  endforeach()
  if(AMPI_ARCH_X86)
    target_compile_definitions(${target} PUBLIC AMPI_ARCH_X86=1)
  elseif(AMPI_ARCH_ARM64)
    target_compile_definitions(${target} PUBLIC AMPI_ARCH_ARM64=1)
  endif()
endfunction()
