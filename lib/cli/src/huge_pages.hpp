#pragma once
// Transparent huge pages for the CT-sized buffers of the commands that hold
// them. On a kernel that gives huge pages only where a program asks
// (transparent_hugepage "madvise", Debian's default), every 4 KiB of a
// freshly allocated volume costs a page fault: on the thorax CT (512 x 512 x
// 141) faults took half of the segment stage's time, and glibc's own switch
// (the tunable glibc.malloc.hugetlb=1, which advises huge pages on its large
// blocks: ours, ITK's, VTK's, GDCM's) halved it. A tunable is read when a
// program starts, hence a restart.

namespace articula::cli {

/// Starts this program again, in place (same pid, same arguments), with
/// glibc.malloc.hugetlb=1 added to GLIBC_TUNABLES, where that helps: the
/// kernel's mode is "madvise" and the variable does not already name the
/// tunable (the user's choice, glibc.malloc.hugetlb=0, is kept). Returns
/// only where nothing is to be done or the restart failed; a program built
/// with AddressSanitizer, whose allocator ignores the tunable, never restarts.
void restartWithHugePages(char** argv);

}  // namespace articula::cli
