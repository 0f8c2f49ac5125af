# Finds the parts of SuiteSparse lptv uses (KLU, UMFPACK and what they need).
# Debian's SuiteSparse 5.x ships no CMake config, hence this module. Defines
# LptvSuiteSparse::KLU and LptvSuiteSparse::UMFPACK.
find_path(LptvSuiteSparse_INCLUDE_DIR klu.h PATH_SUFFIXES suitesparse)
foreach(_lib klu umfpack amd colamd btf cholmod suitesparseconfig)
  string(TOUPPER ${_lib} _LIB)
  find_library(LptvSuiteSparse_${_LIB}_LIBRARY NAMES ${_lib})
endforeach()
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(LptvSuiteSparse REQUIRED_VARS
  LptvSuiteSparse_INCLUDE_DIR LptvSuiteSparse_KLU_LIBRARY LptvSuiteSparse_UMFPACK_LIBRARY
  LptvSuiteSparse_AMD_LIBRARY LptvSuiteSparse_COLAMD_LIBRARY LptvSuiteSparse_BTF_LIBRARY
  LptvSuiteSparse_SUITESPARSECONFIG_LIBRARY)
if(LptvSuiteSparse_FOUND)
  foreach(_lib SUITESPARSECONFIG AMD COLAMD BTF CHOLMOD)
    if(LptvSuiteSparse_${_lib}_LIBRARY AND NOT TARGET LptvSuiteSparse::${_lib})
      add_library(LptvSuiteSparse::${_lib} UNKNOWN IMPORTED)
      set_target_properties(LptvSuiteSparse::${_lib} PROPERTIES
        IMPORTED_LOCATION ${LptvSuiteSparse_${_lib}_LIBRARY}
        INTERFACE_INCLUDE_DIRECTORIES ${LptvSuiteSparse_INCLUDE_DIR})
    endif()
  endforeach()
  if(NOT TARGET LptvSuiteSparse::KLU)
    add_library(LptvSuiteSparse::KLU UNKNOWN IMPORTED)
    set_target_properties(LptvSuiteSparse::KLU PROPERTIES
      IMPORTED_LOCATION ${LptvSuiteSparse_KLU_LIBRARY}
      INTERFACE_INCLUDE_DIRECTORIES ${LptvSuiteSparse_INCLUDE_DIR}
      INTERFACE_LINK_LIBRARIES "LptvSuiteSparse::BTF;LptvSuiteSparse::AMD;LptvSuiteSparse::COLAMD;LptvSuiteSparse::SUITESPARSECONFIG")
  endif()
  if(NOT TARGET LptvSuiteSparse::UMFPACK)
    add_library(LptvSuiteSparse::UMFPACK UNKNOWN IMPORTED)
    set(_umf_deps "LptvSuiteSparse::AMD;LptvSuiteSparse::SUITESPARSECONFIG")
    if(TARGET LptvSuiteSparse::CHOLMOD)
      list(APPEND _umf_deps LptvSuiteSparse::CHOLMOD)
    endif()
    set_target_properties(LptvSuiteSparse::UMFPACK PROPERTIES
      IMPORTED_LOCATION ${LptvSuiteSparse_UMFPACK_LIBRARY}
      INTERFACE_INCLUDE_DIRECTORIES ${LptvSuiteSparse_INCLUDE_DIR}
      INTERFACE_LINK_LIBRARIES "${_umf_deps}")
  endif()
endif()
mark_as_advanced(LptvSuiteSparse_INCLUDE_DIR)
