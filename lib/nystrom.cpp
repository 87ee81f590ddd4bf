// The separately compiled part of nystrom (see include/nystrom/core/config.hpp): the catalog and
// method_data_for, compiled once for every program of this repository's build (CMake option
// NYSTROM_SEPARATE_COMPILATION, target nystrom_compiled) instead of in each translation unit.
#ifndef NYSTROM_SEPARATE_COMPILATION
#error "lib/nystrom.cpp is compiled with NYSTROM_SEPARATE_COMPILATION defined (target nystrom_compiled)"
#endif

#include "nystrom/methods/impl/catalog.ipp"
#include "nystrom/methods/impl/method_data.ipp"
