#pragma once
// What ITK does not check of a MetaImage (.mha, .mhd) or NRRD (.nrrd, .nhdr)
// file: that its voxel data is as long as its header announces. ITK reads a
// file cut short without a word, the missing voxels left as they were.
#include <filesystem>

namespace articula::imaging {

/// Throws InputError, naming both lengths, when the raw or zlib/gzip
/// compressed voxel data of a MetaImage or NRRD file (attached or in its
/// data file) is shorter than its header's sizes and type make it. Other
/// formats, and encodings ITK checks itself (text, lists of files): no-op.
void checkImageDataLength(const std::filesystem::path& path);

}  // namespace articula::imaging
