// Build configuration of the library.
//
// nystrom is header-only: including a header is all a user needs. A few non-template functions are
// large and used almost everywhere: the method catalog (every coefficient table, the specification
// parser, method files) and method_data_for (the refinement of decimal tables). Header-only, each
// translation unit that calls them compiles them again. Defining NYSTROM_SEPARATE_COMPILATION turns
// their headers into declarations; their definitions (methods/impl/*.ipp) are then compiled once, in
// lib/nystrom.cpp, which must be linked (the build of this repository does so for the tool, the tests
// and the benchmarks: CMake option NYSTROM_SEPARATE_COMPILATION, target nystrom_compiled). The
// installed package is header-only.
#pragma once

#ifdef NYSTROM_SEPARATE_COMPILATION
#define NYSTROM_DECL
#else
#define NYSTROM_DECL inline
#endif
