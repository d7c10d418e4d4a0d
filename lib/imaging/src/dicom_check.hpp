#pragma once
// A structural check of one DICOM file before GDCM reads it. Hand-written
// because GDCM (Debian's 3.0, built with assertions) aborts the process on a
// file cut inside its meta header, and reads a file cut inside its pixel data
// without complaint, leaving ITK to fill the missing voxels: neither can be
// caught from the outside. The check walks the data elements (explicit or
// implicit VR, either byte order, sequences and encapsulated pixel data of
// undefined length) without decoding any value, and asks only whether each
// element fits in the file.
#include <filesystem>
#include <string>

namespace articula::imaging {

enum class DicomFileKind {
  Complete,     // every element ends within the file
  Damaged,      // looks like DICOM (a "DICM" preamble) but an element runs past the end, or the structure is broken
  NotDicom,     // no preamble: left to GDCM, which skips what it cannot read
};

struct DicomFileCheck {
  DicomFileKind kind = DicomFileKind::NotDicom;
  std::string problem;  // for Damaged: where and what, e.g. "element (7FE0,0010) at byte 1164 needs 10240 bytes, 36 remain"
};

DicomFileCheck checkDicomFile(const std::filesystem::path& file);

}  // namespace articula::imaging
