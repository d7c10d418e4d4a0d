#pragma once
// Private to lib/imaging: copies between the plain Image<T> and itk::Image<T, 3>
// (buffers are both i-fastest, so a straight copy), and ITK file I/O.
// Include after articula/imaging/image.hpp (system Eigen before ITK's bundled one).
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <string>
#include <unistd.h>

#include <itkImage.h>
#include <itkImageFileReader.h>
#include <itkImageFileWriter.h>
#include <itkMetaImageIO.h>
#include <itkNiftiImageIO.h>
#include <itkNrrdImageIO.h>

#include "articula/core/atomic_file.hpp"
#include "articula/core/error.hpp"
#include "articula/core/excerpt.hpp"
#include "articula/imaging/image.hpp"
#include "image_file_check.hpp"

namespace articula::imaging {

template <typename T>
typename itk::Image<T, 3>::Pointer toItk(const Image<T>& image) {
  using ItkImage = itk::Image<T, 3>;
  const ImageGeometry& g = image.geometry;
  auto out = ItkImage::New();
  typename ItkImage::RegionType region;
  typename ItkImage::SizeType size;
  typename ItkImage::SpacingType spacing;
  typename ItkImage::PointType origin;
  typename ItkImage::DirectionType direction;
  for (unsigned a = 0; a < 3; ++a) {
    size[a] = static_cast<itk::SizeValueType>(g.size[static_cast<int>(a)]);
    spacing[a] = g.spacing[static_cast<int>(a)];
    origin[a] = g.origin[static_cast<int>(a)];
    for (unsigned b = 0; b < 3; ++b) direction(a, b) = g.direction(static_cast<int>(a), static_cast<int>(b));
  }
  region.SetSize(size);
  out->SetRegions(region);
  out->SetSpacing(spacing);
  out->SetOrigin(origin);
  out->SetDirection(direction);
  out->Allocate();
  std::copy(image.voxels.begin(), image.voxels.end(), out->GetBufferPointer());
  return out;
}

template <typename T>
ImageGeometry geometryOf(const itk::Image<T, 3>* image) {
  ImageGeometry g;
  const auto region = image->GetLargestPossibleRegion();
  for (int a = 0; a < 3; ++a) {
    const auto ua = static_cast<unsigned>(a);
    g.size[a] = static_cast<int>(region.GetSize()[ua]);
    g.spacing[a] = image->GetSpacing()[ua];
    g.origin[a] = image->GetOrigin()[ua];
    for (int b = 0; b < 3; ++b) g.direction(a, b) = image->GetDirection()(ua, static_cast<unsigned>(b));
  }
  return g;
}

/// Copies any ITK image into Image<T>; the region must start at index 0.
template <typename T, typename U>
Image<T> fromItk(const itk::Image<U, 3>* image) {
  Image<T> out;
  out.geometry = geometryOf(image);
  const U* buffer = image->GetBufferPointer();
  out.voxels.assign(buffer, buffer + out.geometry.voxelCount());
  return out;
}

/// Throws InputError when a NIfTI file's own header (not ITK's reading of
/// it, which puts 1 mm in place of a pixdim of 0 or NaN) gives a spatial
/// voxel size that is not a positive finite number, or when a single-file
/// NIfTI holds fewer bytes than its header promises (ITK zero-fills them).
/// Other formats: no-op.
void checkNiftiFile(const std::filesystem::path& path);

/// The reader of an image file chosen by its extension (null for another).
/// Not ITK's factory: it asks every reader whether it can read the file, and
/// GDCM's, asked of a damaged .nrrd, parsed it and aborted the process.
inline itk::ImageIOBase::Pointer imageIoFor(const std::filesystem::path& path) {
  std::string name = path.filename().string();
  for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const auto ends = [&name](const std::string& ext) {
    return name.size() > ext.size() && name.compare(name.size() - ext.size(), ext.size(), ext) == 0;
  };
  if (ends(".nii") || ends(".nii.gz")) return itk::NiftiImageIO::New().GetPointer();
  if (ends(".nrrd") || ends(".nhdr")) return itk::NrrdImageIO::New().GetPointer();
  if (ends(".mha") || ends(".mhd")) return itk::MetaImageIO::New().GetPointer();
  return nullptr;
}

/// The pixel type an image file stores (UNKNOWNCOMPONENTTYPE when ITK has no reader for it).
inline itk::IOComponentEnum storedComponentType(const std::filesystem::path& path) {
  auto io = imageIoFor(path);
  if (!io) return itk::IOComponentEnum::UNKNOWNCOMPONENTTYPE;
  try {
    io->SetFileName(path.string());
    io->ReadImageInformation();
  } catch (const itk::ExceptionObject&) {
    return itk::IOComponentEnum::UNKNOWNCOMPONENTTYPE;  // readImageFile says why
  }
  return io->GetComponentType();
}

/// The reader of `path`'s format with its header read (no voxels); null when
/// ITK has no reader for its extension. Throws InputError naming the file
/// when the header cannot be read.
inline itk::ImageIOBase::Pointer readImageHeader(const std::filesystem::path& path) {
  const itk::ImageIOBase::Pointer io = imageIoFor(path);
  if (!io) return io;
  try {
    io->SetFileName(path.string());
    io->ReadImageInformation();
  } catch (const itk::ExceptionObject& e) {
    throw InputError("could not read the image header of " + path.string() + ": " + e.GetDescription());
  } catch (const std::exception& e) {
    throw InputError("could not read the image header of " + path.string() + ": " + excerpt(e.what()));
  }
  return io;
}

template <typename T>
Image<T> readImageFile(const std::filesystem::path& path) {
  checkNiftiFile(path);
  checkImageDataLength(path);
  // What the file holds, before ITK reads it as 3-D (it would silently take
  // the first volume of a 4-D image and the first component of a vector).
  const itk::ImageIOBase::Pointer io = readImageHeader(path);
  if (io) {
    for (unsigned d = 3; d < io->GetNumberOfDimensions(); ++d)
      if (io->GetDimensions(d) > 1)
        throw InputError(path.string() + ": expected one 3-D volume, found " + std::to_string(io->GetNumberOfDimensions()) +
                         "-D data with " + std::to_string(io->GetDimensions(d)) + " elements along dimension " +
                         std::to_string(d + 1));
    if (io->GetNumberOfComponents() > 1)
      throw InputError(path.string() + ": expected one value per voxel, found " + std::to_string(io->GetNumberOfComponents()) +
                       " components");
    for (unsigned d = 0; d < std::min(3u, io->GetNumberOfDimensions()); ++d)
      if (!(io->GetSpacing(d) > 0) || !std::isfinite(io->GetSpacing(d)))
        throw InputError(path.string() + ": expected a voxel spacing > 0 mm, found " + std::to_string(io->GetSpacing(d)) +
                         " along axis " + std::to_string(d + 1));
  }
  auto reader = itk::ImageFileReader<itk::Image<T, 3>>::New();
  reader->SetFileName(path.string());
  if (io) reader->SetImageIO(io);
  try {
    reader->Update();
  } catch (const itk::ExceptionObject& e) {
    throw InputError("could not read the image " + path.string() + ": " + e.GetDescription());
  } catch (const std::exception& e) {
    // ITK's readers let the standard library's exceptions out (MetaIO's
    // std::length_error on a garbled ElementDataFile pattern): bad input too.
    throw InputError("could not read the image " + path.string() + ": " + excerpt(e.what()));
  }
  return fromItk<T>(reader->GetOutput());
}

/// ITK chooses the format from the extension, so the temporary file keeps it:
/// temporaryPathFor(path), renamed into place when complete.
template <typename T>
void writeImageFile(const std::filesystem::path& path, const Image<T>& image, bool overwrite) {
  namespace fs = std::filesystem;
  if (!overwrite && fs::exists(path))
    throw UsageError("refusing to overwrite " + path.string() + " (use --force)");
  const fs::path folder = path.has_parent_path() ? path.parent_path() : fs::path(".");
  std::error_code ec;
  fs::create_directories(folder, ec);
  const fs::path temp = temporaryPathFor(path);
  auto writer = itk::ImageFileWriter<itk::Image<T, 3>>::New();
  writer->SetInput(toItk(image));
  writer->SetFileName(temp.string());
  writer->UseCompressionOn();
  try {
    writer->Update();
  } catch (const itk::ExceptionObject& e) {
    fs::remove(temp, ec);
    throw InputError("could not write " + path.string() + ": " + e.GetDescription());
  }
  fs::rename(temp, path, ec);
  if (ec) {
    fs::remove(temp, ec);
    throw InputError("could not rename the finished image to " + path.string());
  }
}

}  // namespace articula::imaging
