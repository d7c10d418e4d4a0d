#pragma once
// A structural check of one DICOM file before GDCM reads it. Hand-written
// because GDCM (Debian's 3.0, built with assertions) aborts the process on a
// file cut inside its meta header, and reads a file cut inside its pixel data
// without complaint, leaving ITK to fill the missing voxels: neither can be
// caught from the outside. The check walks the data elements (explicit or
// implicit VR, either byte order, sequences and encapsulated pixel data of
// undefined length) without decoding any value, and asks only whether each
// element fits in the file.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace articula::imaging {

enum class DicomFileKind {
  Complete,     // every element ends within the file
  Damaged,      // looks like DICOM (a "DICM" preamble, or a data set's first group) but an element runs past the end, or the structure is broken
  NotDicom,     // neither: left to GDCM, which skips what it cannot read
};

/// What a slice's top-level data set says about its place and its pixels,
/// as written (empty text or -1 where the element is absent).
struct DicomSliceHeader {
  bool read = false;  // the data set was walked to its end
  bool bare = false;  // a data set without the preamble and meta header of a DICOM file
  std::string position, orientation, pixel_spacing, rescale_slope, frames, slice_thickness;  // DS/IS text
  std::string series_uid, modality, description;
  long rows = -1, columns = -1, bits_allocated = -1, samples_per_pixel = -1;
  long bits_stored = -1, high_bit = -1, pixel_representation = -1;
  static constexpr std::int64_t kEncapsulated = -2;
  std::int64_t pixel_data_bytes = -1;  // -1: no Pixel Data; kEncapsulated: compressed fragments
};

struct DicomFileCheck {
  DicomFileKind kind = DicomFileKind::NotDicom;
  std::string problem;  // for Damaged: where and what, e.g. "element (7FE0,0010) at byte 1164 needs 10240 bytes, 36 remain"
  DicomSliceHeader header;
};

DicomFileCheck checkDicomFile(const std::filesystem::path& file);

/// The numbers of a DS/IS text ("1\0\0"); empty when any is not a finite number.
std::vector<double> dicomNumbers(const std::string& text);

/// A folder's DICOM images as series, from the walk alone: GDCM then reads
/// only files that passed it (it aborts the process on some it cannot parse,
/// and takes files of any content for DICOM). Images (files with pixel data)
/// are grouped by Series Instance UID, in UID order; each series' files are
/// in order along the slice normal of its first file (by name), then by name.
struct DicomFolder {
  struct Series {
    std::string uid;  // empty for files whose UID is empty
    std::string modality, description;
    std::vector<std::string> files;  // paths
    std::vector<DicomSliceHeader> headers;
  };
  std::vector<Series> series;
  std::vector<std::string> other_files;  // names: no DICOM, DICOM without pixel data, or bare data sets
  int bare_files = 0;                    // data sets without the preamble and meta header (left out)
  std::vector<std::string> damaged;      // "name: problem", the first five
  int damaged_count = 0;
};
DicomFolder scanDicomFolder(const std::filesystem::path& folder);

/// Every slice of a series against the first, before ITK assembles them: ITK
/// takes the size, spacing and orientation of the first slice (and positions
/// along the slice normal) for all, and fills what a slice lacks. Refuses
/// (InputError, the file named) slices whose rows, columns, bits, orientation,
/// pixel spacing or in-plane position differ, pixel data shorter than its
/// header announces, a zero rescale slope, duplicated positions, and a volume
/// larger than this machine's memory.
void checkSeriesHeaders(const std::vector<std::string>& files, const std::vector<DicomSliceHeader>& headers);

}  // namespace articula::imaging
