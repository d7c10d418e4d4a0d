#pragma once
// Forced in front of every source of this module when building with Clang
// (lib/imaging/CMakeLists.txt): ITK 5.2 as Debian packages it carries the
// compiler feature table of GCC only, and its itk_compiler_detection.h stops
// with "Unsupported compiler" on Clang. Clang has every C++ feature the GCC
// table tests for, so the table is read once with Clang presenting itself as
// GCC 12; the include guard keeps that result for ITK's own includes.
#if defined(__clang__)
#pragma push_macro("__clang__")
#pragma push_macro("__GNUC__")
#pragma push_macro("__GNUC_MINOR__")
#undef __clang__
#undef __GNUC__
#undef __GNUC_MINOR__
#define __GNUC__ 12
#define __GNUC_MINOR__ 2
#include <itk_compiler_detection.h>
#pragma pop_macro("__GNUC_MINOR__")
#pragma pop_macro("__GNUC__")
#pragma pop_macro("__clang__")
#endif
