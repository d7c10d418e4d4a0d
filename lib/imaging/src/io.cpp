// ITK reading and writing of CT volumes and labels. ITK bundles its own Eigen
// under the system Eigen's include guards: image.hpp (system Eigen) comes first.
#include "articula/imaging/io.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iomanip>
#include <limits>
#include <sstream>
#include <vector>
#include <unistd.h>

#include <gdcmTrace.h>
#include <gdcmUIDGenerator.h>
#include <itkGDCMImageIO.h>
#include <itkImage.h>
#include <itkVersion.h>
#include <itkMultiThreaderBase.h>
#include <cerrno>
#include <cstdint>
#include <itkImageFileReader.h>
#include <zlib.h>
#include <itkImageFileWriter.h>
#include <itkImageSeriesReader.h>
#include <itkImageSeriesWriter.h>

#include "articula/core/error.hpp"
#include "articula/core/excerpt.hpp"
#include "articula/core/log.hpp"
#include "dicom_check.hpp"
#include "itk_bridge.hpp"

namespace articula::imaging {
namespace fs = std::filesystem;

namespace {

// Where a NIfTI header puts its voxels, as its qform and its sform: empty
// when they agree (or only one is set), the problem otherwise. Without either,
// ITK falls back to Analyze's convention (no origin, no orientation), and a
// header whose two transforms disagree reads differently in different tools:
// a right hip may read as a left one.
struct NiftiPlacement {
  int qform_code = 0, sform_code = 0;
  double pixdim[4] = {};  // qfac, then the voxel sizes
  double quatern[6] = {};  // b, c, d, then the offsets x, y, z
  double srow[12] = {};
  double dims[3] = {};
};

std::string niftiPlacementProblem(const NiftiPlacement& n) {
  if (n.qform_code <= 0 && n.sform_code <= 0)
    return "states no orientation (qform_code and sform_code are 0), so its voxels have no place in the patient "
           "(no origin, no left or right); expected a qform or an sform: convert the DICOM series again (for "
           "example with dcm2niix) or set the transform with the tool that wrote the file";
  if (n.qform_code <= 0 || n.sform_code <= 0) return "";
  const double b = n.quatern[0], c = n.quatern[1], d = n.quatern[2];
  const double a = std::sqrt(std::max(0.0, 1 - (b * b + c * c + d * d)));
  const Eigen::Matrix3d rotation{{a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c)},
                                 {2 * (b * c + a * d), a * a + c * c - b * b - d * d, 2 * (c * d - a * b)},
                                 {2 * (b * d - a * c), 2 * (c * d + a * b), a * a + d * d - c * c - b * b}};
  const double qfac = n.pixdim[0] < 0 ? -1 : 1;
  const Eigen::Matrix3d q = rotation * Eigen::Vector3d(n.pixdim[1], n.pixdim[2], qfac * n.pixdim[3]).asDiagonal();
  const Eigen::Vector3d q_origin(n.quatern[3], n.quatern[4], n.quatern[5]);
  Eigen::Matrix3d s;
  Eigen::Vector3d s_origin;
  for (int r = 0; r < 3; ++r) {
    s.row(r) << n.srow[4 * r], n.srow[4 * r + 1], n.srow[4 * r + 2];
    s_origin[r] = n.srow[4 * r + 3];
  }
  double apart = 0;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d index((corner & 1) ? n.dims[0] - 1 : 0, (corner & 2) ? n.dims[1] - 1 : 0,
                                (corner & 4) ? n.dims[2] - 1 : 0);
    apart = std::max(apart, (q * index + q_origin - (s * index + s_origin)).norm());
  }
  const double voxel = std::min({std::fabs(n.pixdim[1]), std::fabs(n.pixdim[2]), std::fabs(n.pixdim[3])});
  if (!(apart > 0.5 * voxel)) return "";
  std::ostringstream m;
  m << std::setprecision(4) << "places its voxels two ways: its qform and its sform put a corner of the volume "
    << apart << " mm apart" << (q.determinant() * s.determinant() < 0 ? " (one mirrors the other)" : "")
    << ", and tools differ in which they use; expected transforms that agree: rewrite the header with the right "
       "one in both (for example nibabel's img.set_qform(img.get_sform()))";
  return m.str();
}

}  // namespace

void checkNiftiFile(const fs::path& path) {
  const std::string name = path.filename().string();
  const auto ends = [&name](const std::string& ext) {
    return name.size() > ext.size() && name.compare(name.size() - ext.size(), ext.size(), ext) == 0;
  };
  if (!ends(".nii") && !ends(".nii.gz")) return;
  // zlib reads plain and gzip files alike; the header is the first 348
  // (NIfTI-1) or 540 (NIfTI-2) bytes, in the file's byte order.
  gzFile file = gzopen(path.string().c_str(), "rb");
  if (!file) throw InputError("cannot open '" + path.string() + "': " + std::strerror(errno));
  unsigned char header[540] = {};
  const int got = gzread(file, header, sizeof header);
  if (got < 348) {
    gzclose(file);
    throw InputError(path.string() + ": expected a NIfTI header of 348 bytes, found " + std::to_string(std::max(got, 0)));
  }
  const auto bytes = [&header](int at, int n, bool swap) {
    std::uint64_t v = 0;
    for (int i = 0; i < n; ++i) v |= std::uint64_t(header[at + (swap ? i : n - 1 - i)]) << (8 * (n - 1 - i));
    return v;  // little-endian read unless swapped
  };
  for (bool order : {false, true}) {
    const auto size = static_cast<std::int32_t>(bytes(0, 4, order));
    if (size != 348 && !(size == 540 && got >= 540)) continue;
    // A NIfTI-2 header says so by its size and its magic "n+2"; nifti1_io
    // reads any other header in NIfTI-1's layout (without "n+1", as Analyze),
    // and so it is checked here.
    const bool v1 = !(size == 540 && std::memcmp(header + 4, "n+2", 3) == 0);
#if ITK_VERSION_MAJOR < 5 || (ITK_VERSION_MAJOR == 5 && ITK_VERSION_MINOR < 3)
    // Before 5.3 ITK reads NIfTI-1 only: a NIfTI-2 file it takes for an
    // Analyze image in NIfTI-1's layout, other dimensions than the file's
    // (a 553-byte file asked for 1.5 GB).
    if (!v1) {
      gzclose(file);
      throw InputError(path.string() + ": a NIfTI-2 header (540 bytes, magic n+2), which the ITK " +
                       itk::Version::GetITKVersion() + " of this build does not read; expected NIfTI-1: convert it " +
                       "(for example nibabel's nib.Nifti1Image(img.dataobj, img.affine).to_filename(...))");
    }
#endif
    // ITK reads NIfTI-1 with nifti1_io, which takes the byte order from dim[0]
    // unless it is 0 (and only then from the header size): every field below
    // is read in the order ITK will use, or the checks would judge other
    // numbers than those ITK allocates for.
    bool swap = order;
    if (v1) {
      const auto dim0 = static_cast<std::int16_t>(bytes(40, 2, false));
      const auto dim0_swapped = static_cast<std::int16_t>(bytes(40, 2, true));
      if (dim0 >= 1 && dim0 <= 7) {
        swap = false;
      } else if (dim0_swapped >= 1 && dim0_swapped <= 7) {
        swap = true;
      } else {
        gzclose(file);
        throw InputError(path.string() + ": the NIfTI header's dim[0] (the number of dimensions) is " +
                         std::to_string(dim0) + "; expected 1 to 7");
      }
    }
    const auto real = [&](int at) {
      if (v1) {
        const auto bits = static_cast<std::uint32_t>(bytes(at, 4, swap));
        float f;
        std::memcpy(&f, &bits, 4);
        return double(f);
      }
      const std::uint64_t bits = bytes(at, 8, swap);
      double d;
      std::memcpy(&d, &bits, 8);
      return d;
    };
    const auto dim = [&](int i) {
      return v1 ? double(static_cast<std::int16_t>(bytes(40 + 2 * i, 2, swap)))
                : double(static_cast<std::int64_t>(bytes(16 + 8 * i, 8, swap)));
    };
    for (int axis = 1; axis <= 3; ++axis) {
      const double spacing = real((v1 ? 76 : 104) + (v1 ? 4 : 8) * axis);
      if (!(std::isfinite(spacing) && spacing != 0 && std::fabs(spacing) <= 1e4)) {
        gzclose(file);
        throw InputError(path.string() + ": the NIfTI header's pixdim[" + std::to_string(axis) +
                         "] (voxel size along axis " + std::to_string(axis) + ") is " + std::to_string(spacing) +
                         "; expected a non-zero size of at most 1e4 mm");
      }
    }
    // ITK builds the orientation from pixdim[0] (qfac), the quaternion, its
    // offsets and the sform rows: it aborts the process (vnl's assert_finite)
    // on a NaN or an infinity among them, and its SVD never ends on values
    // near the float range. A kilometre bounds any real offset or sform entry.
    const int width = v1 ? 4 : 8;
    std::vector<int> orientation_bytes = {v1 ? 76 : 104};
    for (int k = 0; k < 18; ++k) orientation_bytes.push_back((v1 ? 256 : 352) + width * k);
    for (int at : orientation_bytes)
      if (!(std::fabs(real(at)) <= 1e6)) {
        gzclose(file);
        throw InputError(path.string() + ": the NIfTI header's orientation (pixdim[0], quatern, qoffset, srow) holds " +
                         std::to_string(real(at)) + " at byte " + std::to_string(at) +
                         "; expected finite numbers of at most 1e6 in size");
      }
    NiftiPlacement placement;
    placement.qform_code = v1 ? static_cast<std::int16_t>(bytes(252, 2, swap)) : static_cast<std::int32_t>(bytes(344, 4, swap));
    placement.sform_code = v1 ? static_cast<std::int16_t>(bytes(254, 2, swap)) : static_cast<std::int32_t>(bytes(348, 4, swap));
    for (int i = 0; i < 4; ++i) placement.pixdim[i] = real((v1 ? 76 : 104) + width * i);
    for (int k = 0; k < 6; ++k) placement.quatern[k] = real((v1 ? 256 : 352) + width * k);
    for (int k = 0; k < 12; ++k) placement.srow[k] = real((v1 ? 256 : 352) + width * (6 + k));
    for (int i = 0; i < 3; ++i) placement.dims[i] = std::max(dim(i + 1), 1.0);
    if (const std::string problem = niftiPlacementProblem(placement); !problem.empty()) {
      gzclose(file);
      throw InputError(path.string() + ": the NIfTI header " + problem);
    }
    // A .nii file must hold all its voxels: ITK allocates the whole image from
    // the header before it reads any voxel (a header of 10^9 voxels in a file
    // of a few bytes asked for gigabytes), and it reads a truncated file (or a
    // truncated gzip stream) without complaint, filling the rest with zeros.
    // So the stream is measured here, at the cost of one more decompression.
    // For NIfTI-1 this holds whatever the magic says: ITK reads a .nii without
    // "n+1" as an Analyze image, from the same file.
    const double rank = dim(0);
    const auto datatype = static_cast<std::int16_t>(bytes(v1 ? 70 : 12, 2, swap));
    const double bitpix = double(static_cast<std::int16_t>(bytes(v1 ? 72 : 14, 2, swap)));
    // Bytes per voxel as nifti1_io takes them, from the datatype; bitpix only
    // for a datatype it does not know (then it refuses the file anyway).
    double voxel_bytes = 0;
    switch (datatype) {
      case 2: case 256: voxel_bytes = 1; break;                      // uint8, int8
      case 4: case 512: voxel_bytes = 2; break;                      // int16, uint16
      case 128: voxel_bytes = 3; break;                              // rgb24
      case 8: case 16: case 768: case 2304: voxel_bytes = 4; break;  // int32, float32, uint32, rgba32
      case 32: case 64: case 1024: case 1280: voxel_bytes = 8; break;  // complex64, float64, int64, uint64
      case 1536: case 1792: voxel_bytes = 16; break;                 // float128, complex128
      case 2048: voxel_bytes = 32; break;                            // complex256
      default: voxel_bytes = std::max(bitpix / 8, 1.0);
    }
    const double stored_offset = v1 ? real(108) : double(static_cast<std::int64_t>(bytes(168, 8, swap)));
    // The voxels start after the header, whatever the header says.
    const double offset = std::isfinite(stored_offset) ? std::max(stored_offset, double(size)) : double(size);
    if (rank >= 1 && rank <= 7) {
      // Counts for messages; a header may promise more than a long long holds.
      const auto number = [](double v) {
        if (v < 9e18) return std::to_string(std::llround(v));
        std::ostringstream text;
        text << v;
        return text.str();
      };
      double voxels = 1;
      for (int i = 1; i <= rank; ++i) voxels *= std::max(dim(i), 1.0);
      const double expected = offset + voxels * voxel_bytes;
      double found = got;
      std::vector<unsigned char> chunk(1 << 20);
      for (int n; found < expected && (n = gzread(file, chunk.data(), static_cast<unsigned>(chunk.size()))) > 0;)
        found += n;
      int zerr = Z_OK;
      // zlib owns the message and frees it with the stream: copied before gzclose.
      const char* zmessage = gzerror(file, &zerr);
      std::string zlib_message = zmessage && *zmessage ? zmessage : "zlib error";
      // gzerror puts the file name first; the message names it already.
      if (zlib_message.rfind(path.string() + ": ", 0) == 0) zlib_message.erase(0, path.string().size() + 2);
      gzclose(file);
      if (zerr != Z_OK && zerr != Z_STREAM_END)
        throw InputError(path.string() + ": the compressed data is damaged after " + number(found) +
                         " bytes (" + excerpt(zlib_message) + "); expected " +
                         number(expected) + " bytes of header and voxels");
      if (found < expected)
        throw InputError(path.string() + ": truncated: expected " + number(expected) +
                         " bytes of header and voxels (" + number(voxels) + " voxels of " +
                         number(voxel_bytes * 8) + " bits), found " +
                         number(found));
      return;
    }
    gzclose(file);
    return;
  }
  gzclose(file);
  throw InputError(path.string() + ": not a NIfTI file (its header size is neither 348 nor 540 in either byte order)");
}

namespace {

std::string seriesList(const std::vector<SeriesInfo>& series) {
  std::string out;
  for (const auto& s : series)
    out += "\n  " + s.uid + "  modality " + (s.modality.empty() ? "?" : s.modality) + ", " +
           std::to_string(s.files) + " files" + (s.description.empty() ? "" : ", '" + s.description + "'");
  return out;
}

bool isImageFile(const fs::path& p) {
  const std::string name = p.filename().string();
  for (const char* ext : {".nii", ".nii.gz", ".nrrd", ".nhdr", ".mha", ".mhd"})
    if (name.size() > std::strlen(ext) && name.compare(name.size() - std::strlen(ext), std::string::npos, ext) == 0)
      return true;
  return false;
}

std::string unreadableList(const ReadReport& report) {
  std::string list;
  for (size_t i = 0; i < report.unreadable_files.size() && i < 5; ++i)
    list += (i ? ", " : "") + excerpt(report.unreadable_files[i]);
  return list + (report.unreadable_files.size() > 5 ? ", ..." : "");
}

/// Measures slice gaps and gantry tilt from Image Position/Orientation Patient
/// of every slice (as the walk read them), refusing gaps or tilt that ITK
/// would silently mis-place, before ITK decodes any slice.
void checkSlices(const std::vector<std::string>& files, const std::vector<DicomSliceHeader>& headers,
                 const ReadOptions& options, ReadReport& report, double& spacing_out) {
  const std::vector<double> iop = dicomNumbers(headers.at(0).orientation);
  if (iop.size() != 6) throw InputError("DICOM series: missing Image Orientation Patient (0020,0037) in " + files[0]);
  const Eigen::Vector3d row(iop[0], iop[1], iop[2]), col(iop[3], iop[4], iop[5]);
  const Eigen::Vector3d normal = row.cross(col).normalized();
  std::vector<Eigen::Vector3d> positions;
  for (size_t k = 0; k < files.size(); ++k) {
    const std::vector<double> ipp = dicomNumbers(headers[k].position);
    if (ipp.size() != 3) throw InputError("DICOM series: missing Image Position Patient (0020,0032) in " + files[k]);
    positions.emplace_back(ipp[0], ipp[1], ipp[2]);
  }
  if (positions.size() < 2) throw InputError("DICOM series: a volume needs at least 2 slices, found 1 (" + files[0] + ")");
  std::vector<double> gaps;
  for (size_t k = 0; k + 1 < positions.size(); ++k) gaps.push_back(normal.dot(positions[k + 1] - positions[k]));
  std::vector<double> sorted = gaps;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2), sorted.end());
  const double median = sorted[sorted.size() / 2];
  if (std::fabs(median) < 1e-6) throw InputError("DICOM series: slices share one position (duplicated slices?) in " + files[0]);
  double spread = 0;
  for (size_t k = 0; k < gaps.size(); ++k) {
    spread = std::max(spread, std::fabs(gaps[k] - median));
    if (std::fabs(gaps[k] - median) > options.spacing_tolerance * std::fabs(median) + 1e-3) {
      std::ostringstream m;
      m << "DICOM series: non-uniform slice spacing: expected " << std::fabs(median) << " mm between slices, found "
        << std::fabs(gaps[k]) << " mm between " << fs::path(files[k]).filename().string() << " and "
        << fs::path(files[k + 1]).filename().string() << (std::fabs(gaps[k]) > 1.5 * std::fabs(median) ? " (missing slice?)" : "");
      if (!report.unreadable_files.empty())
        m << "; the folder holds " << report.unreadable_files.size()
          << " file(s) that could not be read as DICOM: " << unreadableList(report);
      throw InputError(m.str());
    }
  }
  const Eigen::Vector3d span = positions.back() - positions.front();
  const double tilt = std::acos(std::min(1.0, std::fabs(span.normalized().dot(normal)))) * 180.0 / M_PI;
  report.gantry_tilt_deg = tilt;
  if (tilt > options.tilt_tolerance_deg) {
    std::ostringstream m;
    m << "DICOM series: gantry tilt of " << tilt << " degrees (slice positions do not follow the slice normal); "
      << "ITK would place the slices sheared. Resample the series to an orthogonal grid first.";
    throw InputError(m.str());
  }
  report.slice_spacing_mm = std::fabs(median);
  report.slice_spacing_spread_mm = spread;
  spacing_out = std::fabs(median);
}

/// The thickness the slices state (Slice Thickness, 0018,0050): their median,
/// 0 where none states one. Kept as the voxels' extent across the slices
/// where it departs from the spacing by more than a per cent (slices
/// reconstructed thicker than their spacing overlap; thinner ones leave
/// gaps) and lies within a quarter to four times it; beyond, it is taken
/// for a wrong tag and named in a warning.
void readSliceThickness(const std::vector<DicomSliceHeader>& headers, double spacing_mm, ReadReport& report,
                        ImageGeometry& geometry) {
  std::vector<double> stated;
  for (const DicomSliceHeader& h : headers) {
    const std::vector<double> t = dicomNumbers(h.slice_thickness);
    if (t.size() == 1 && t[0] > 0) stated.push_back(t[0]);
  }
  if (stated.empty()) return;
  std::sort(stated.begin(), stated.end());
  const double thickness = stated[stated.size() / 2];
  report.slice_thickness_mm = thickness;
  std::ostringstream m;
  if (stated.back() > 1.01 * stated.front())
    m << "the slices state thicknesses from " << stated.front() << " to " << stated.back() << " mm; their median "
      << thickness << " mm is used";
  if (std::fabs(thickness - spacing_mm) > 0.01 * spacing_mm) {
    if (thickness >= 0.25 * spacing_mm && thickness <= 4 * spacing_mm) {
      geometry.slice_thickness_mm = thickness;
    } else {
      m << (m.tellp() > 0 ? "; " : "") << "Slice Thickness (0018,0050) states " << thickness
        << " mm against slices " << spacing_mm << " mm apart: not taken as the slices' extent";
    }
  }
  if (m.tellp() > 0) report.warnings.push_back("DICOM series: " + m.str());
}

// Files of the folder in no series (no DICOM image): named in a warning
// (the segmentation's summary keeps it), and in the message when the series
// then lacks a slice.
void noteUnreadableFiles(const fs::path& folder, const DicomFolder& scan, ReadReport& report) {
  report.unreadable_files = scan.other_files;
  if (!report.unreadable_files.empty())
    report.warnings.push_back(std::to_string(report.unreadable_files.size()) + " file(s) of " + folder.string() +
                              " are in no DICOM series (not DICOM, no image, or unreadable): " + unreadableList(report));
}

DicomFolder scanSeries(const fs::path& folder);
std::vector<SeriesInfo> seriesOf(const DicomFolder& scan);

Volume readDicom(const fs::path& folder, const ReadOptions& options, ReadReport& report) {
  report.source = "dicom";
  const DicomFolder scan = scanSeries(folder);
  report.series = seriesOf(scan);
  const SeriesInfo* chosen = nullptr;
  if (!options.series_uid.empty()) {
    for (const auto& s : report.series)
      if (s.uid == options.series_uid) chosen = &s;
    if (!chosen)
      throw InputError("--series-uid " + options.series_uid + " not found in " + folder.string() +
                       "; series found:" + seriesList(report.series));
  } else {
    std::vector<const SeriesInfo*> ct;
    for (const auto& s : report.series)
      if (s.modality == "CT" || s.modality.empty()) ct.push_back(&s);
    if (ct.empty())
      throw InputError("expected a CT series in " + folder.string() + ", found only other modalities:" +
                       seriesList(report.series));
    if (ct.size() > 1)
      throw InputError("several CT series in " + folder.string() + "; choose one with --series-uid:" +
                       seriesList(report.series));
    chosen = ct.front();
    if (report.series.size() > 1) log::info("using the CT series " + chosen->uid + " (" + std::to_string(chosen->files) + " files)");
  }
  if (!chosen->modality.empty() && chosen->modality != "CT")
    throw InputError("expected modality CT, found " + chosen->modality + " in series " + chosen->uid + " of " +
                     folder.string());
  if (chosen->modality.empty()) report.warnings.push_back("series has no Modality tag; assumed CT");
  report.series_uid = chosen->uid;
  report.modality = chosen->modality;

  const DicomFolder::Series& slices = scan.series[static_cast<size_t>(chosen - report.series.data())];
  const std::vector<std::string>& files = slices.files;
  noteUnreadableFiles(folder, scan, report);
  checkSeriesHeaders(files, slices.headers);
  double spacing_z = 0;
  checkSlices(files, slices.headers, options, report, spacing_z);
  using ReaderType = itk::ImageSeriesReader<itk::Image<float, 3>>;
  auto reader = ReaderType::New();
  auto io = itk::GDCMImageIO::New();
  reader->SetImageIO(io);
  reader->SetFileNames(files);
  try {
    reader->Update();
  } catch (const itk::ExceptionObject& e) {
    throw InputError("could not decode the DICOM series " + chosen->uid + " in " + folder.string() +
                     " (unsupported transfer syntax or missing codec?): " + e.GetDescription());
  } catch (const std::exception& e) {
    throw InputError("could not decode the DICOM series " + chosen->uid + " in " + folder.string() + ": " +
                     excerpt(e.what()));
  }
  Volume volume = fromItk<float>(reader->GetOutput());
  volume.geometry.spacing[2] = spacing_z;  // ITK uses the first two slices only
  readSliceThickness(slices.headers, spacing_z, report, volume.geometry);
  return volume;
}

}  // namespace

// Voxels a CT can hold: finite numbers, not all the same (a zero
// RescaleSlope, or a series written blank, gives one value everywhere).
void checkVoxelValues(const Volume& volume, const std::string& where) {
  size_t non_finite = 0;
  float lo = std::numeric_limits<float>::max(), hi = std::numeric_limits<float>::lowest();
  for (const float v : volume.voxels) {
    if (!std::isfinite(v)) {
      ++non_finite;
      continue;
    }
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  if (non_finite > 0)
    throw InputError(where + ": " + std::to_string(non_finite) + " of " + std::to_string(volume.voxels.size()) +
                     " voxels are not finite numbers (NaN or infinite): expected CT values in HU; the file is damaged "
                     "or holds no CT");
  if (!volume.voxels.empty() && lo == hi)
    throw InputError(where + ": every voxel holds the same value (" + std::to_string(lo) +
                     "): a CT of a joint varies; a RescaleSlope of 0 or a blank series gives this");
}

void checkDirection(const Eigen::Matrix3d& direction, const std::string& where) {
  const double err = (direction.transpose() * direction - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!direction.allFinite() || err > 1e-3) {
    std::ostringstream m;
    m << "expected an orthonormal direction matrix in " << where << ", found\n" << direction;
    throw InputError(m.str());
  }
}

std::string dicomFoldersBelow(const fs::path& folder);

namespace {
// Every file of the folder is walked (dicom_check.hpp) and GDCM reads only
// the series found: a damaged DICOM file is refused by name; files that are
// no DICOM image (a README, a DICOMDIR) are left out with a warning.

DicomFolder scanSeries(const fs::path& folder) {
  // GDCM prints its own errors and warnings (a tag it cannot parse) as raw
  // lines; the checks here name the file and say what to do instead.
  gdcm::Trace::ErrorOff();
  gdcm::Trace::WarningOff();
  // ITK's own warnings (e.g. on slices it skipped) would precede ours; what
  // they say is checked and reported here.
  itk::Object::GlobalWarningDisplayOff();
  if (!fs::is_directory(folder)) throw InputError("expected a DICOM folder, found no folder at " + folder.string());
  if (fs::is_empty(folder)) throw InputError("expected DICOM files in " + folder.string() + ", found an empty folder");
  DicomFolder scan = scanDicomFolder(folder);
  if (scan.damaged_count > 0) {
    std::string list;
    for (const auto& d : scan.damaged) list += "\n  " + d;
    throw InputError("expected complete DICOM files in " + folder.string() + ", found " +
                     std::to_string(scan.damaged_count) + " damaged (cut short or corrupted; replace or remove them):" +
                     list + (scan.damaged_count > 5 ? "\n  ..." : ""));
  }
  if (scan.series.empty() && scan.bare_files > 0)
    throw InputError("expected DICOM files in " + folder.string() + ", found " + std::to_string(scan.bare_files) +
                     " bare DICOM data set(s) without the preamble and meta header a DICOM file begins with; rewrite "
                     "them as DICOM files (gdcmconv IN OUT, or dcmconv +F IN OUT) and give that folder");
  if (scan.series.empty())
    throw InputError("expected DICOM files in " + folder.string() + ", found none (no readable DICOM series)" +
                     dicomFoldersBelow(folder));
  return scan;
}

std::vector<SeriesInfo> seriesOf(const DicomFolder& scan) {
  std::vector<SeriesInfo> out;
  for (const auto& series : scan.series) {
    SeriesInfo s;
    s.uid = series.uid.empty() ? kEmptySeriesUid : series.uid;  // choosable by name
    s.files = static_cast<int>(series.files.size());
    s.modality = series.modality;
    s.description = series.description;
    out.push_back(s);
  }
  return out;
}

}  // namespace

// Up to three folders below `folder` (three levels deep, 200 folders at
// most) holding DICOM files, with how many: the hint when a user gives the
// folder above a series.
std::string dicomFoldersBelow(const fs::path& folder) {
  std::vector<std::pair<fs::path, int>> level = {{folder, 0}}, found;
  int visited = 0;
  for (int depth = 0; depth <= 3 && found.size() < 3; ++depth) {
    std::vector<std::pair<fs::path, int>> next;
    for (const auto& [dir, unused] : level) {
      std::error_code ec;
      int dicom = 0, looked = 0;
      for (auto it = fs::directory_iterator(dir, ec); !ec && it != fs::directory_iterator(); it.increment(ec)) {
        if (it->is_directory(ec) && !it->is_symlink(ec)) {
          if (++visited <= 200) next.push_back({it->path(), 0});
        } else if (depth > 0 && it->is_regular_file(ec) && looked < 64) {
          ++looked;
          dicom += checkDicomFile(it->path()).kind != DicomFileKind::NotDicom ? 1 : 0;
        }
      }
      if (dicom > 0 && found.size() < 3) found.push_back({dir, dicom});
    }
    level = std::move(next);
  }
  std::string hint;
  for (const auto& [dir, files] : found)
    hint += (hint.empty() ? "; DICOM files lie in " : ", in ") + dir.string() + " (" +
            (files >= 64 ? "64 or more" : std::to_string(files)) + " files)";
  return hint.empty() ? "" : hint + ": give that folder as the input";
}

std::vector<SeriesInfo> listDicomSeries(const fs::path& folder) { return seriesOf(scanSeries(folder)); }

void limitImagingThreads(int threads) {
  const auto n = static_cast<itk::ThreadIdType>(std::max(1, threads));
  itk::MultiThreaderBase::SetGlobalMaximumNumberOfThreads(n);
  itk::MultiThreaderBase::SetGlobalDefaultNumberOfThreads(n);
}

namespace {

// A read and its report, kept together in a run's memory.
struct KeptRead {
  Volume volume;
  ReadReport report;
};

/// What identifies a read: the input's path and options, and every file's
/// name, size and modification time (a folder's recursively, in name order).
std::string readKey(const fs::path& input, const ReadOptions& options) {
  std::ostringstream key;
  key << fs::absolute(input).string() << '\n' << options.series_uid << '\n' << options.spacing_tolerance << '\n'
      << options.tilt_tolerance_deg << '\n';
  std::error_code ec;
  const auto stamp = [&](const fs::path& file) {
    key << file.string() << ' ' << fs::file_size(file, ec) << ' '
        << fs::last_write_time(file, ec).time_since_epoch().count() << '\n';
  };
  if (fs::is_directory(input, ec)) {
    std::vector<fs::path> files;
    for (const auto& e : fs::recursive_directory_iterator(input, ec))
      if (e.is_regular_file(ec)) files.push_back(e.path());
    std::sort(files.begin(), files.end());
    for (const fs::path& f : files) stamp(f);
  } else {
    stamp(input);
  }
  return key.str();
}

Volume readVolumeFromFiles(const fs::path& input, const ReadOptions& options, ReadReport& report);

}  // namespace

std::shared_ptr<const Volume> readSharedVolume(const fs::path& input, const ReadOptions& options,
                                               ReadReport* report_out, RunMemory* memory) {
  if (!memory) {
    ReadReport report;
    auto volume = std::make_shared<const Volume>(readVolumeFromFiles(input, options, report));
    if (report_out) *report_out = report;
    return volume;
  }
  const std::shared_ptr<const KeptRead> kept = memory->kept<KeptRead>("ct", readKey(input, options), [&] {
    KeptRead read;
    read.volume = readVolumeFromFiles(input, options, read.report);
    return read;
  });
  if (report_out) *report_out = kept->report;
  return {kept, &kept->volume};  // shares the kept read's ownership
}

Volume readVolume(const fs::path& input, const ReadOptions& options, ReadReport* report_out) {
  return *readSharedVolume(input, options, report_out);
}

namespace {

Volume readVolumeFromFiles(const fs::path& input, const ReadOptions& options, ReadReport& report) {
  report = ReadReport{};
  Volume volume;
  if (fs::is_directory(input)) {
    volume = readDicom(input, options, report);
  } else {
    if (!fs::exists(input)) throw InputError("input not found: " + input.string());
    if (!isImageFile(input))
      throw InputError("expected a DICOM folder or a .nii/.nii.gz/.nrrd/.mha file, found " + input.string());
    report.source = "file";
    volume = readImageFile<float>(input);
  }
  checkDirection(volume.geometry.direction, input.string());
  checkVoxelValues(volume, input.string());
  // The head search smooths the volume with ITK's recursive Gaussian, which
  // needs four voxels along each axis; a joint needs many more.
  if (volume.geometry.size.minCoeff() < 4)
    throw InputError("expected a 3-D volume of at least 4 voxels along each axis in " + input.string() + ", found size " +
                     std::to_string(volume.geometry.size[0]) + "x" + std::to_string(volume.geometry.size[1]) + "x" +
                     std::to_string(volume.geometry.size[2]));
  return volume;
}

}  // namespace

ImageGeometry readImageGeometry(const fs::path& input) {
  if (!fs::is_regular_file(input)) throw InputError("image not found: " + input.string());
  const itk::ImageIOBase::Pointer io = readImageHeader(input);
  if (!io) throw InputError("expected an image (.nii.gz/.nii/.nrrd/.mha), found " + input.string());
  if (io->GetNumberOfDimensions() != 3)
    throw InputError("expected a 3-D image, found " + std::to_string(io->GetNumberOfDimensions()) + " dimensions in " +
                     input.string());
  ImageGeometry g;
  for (unsigned a = 0; a < 3; ++a) {
    g.size[a] = static_cast<int>(io->GetDimensions(a));
    g.spacing[a] = io->GetSpacing(a);
    g.origin[a] = io->GetOrigin(a);
    const std::vector<double> column = io->GetDirection(a);
    for (unsigned r = 0; r < 3; ++r) g.direction(r, a) = column[r];
  }
  checkDirection(g.direction, input.string());
  return g;
}

namespace {

/// A label's voxels as its file stores them (uint8), kept in a run's memory.
struct KeptLabel {
  std::vector<std::uint8_t> voxels;
};

/// What identifies a label file in a run: its path, size and modification time.
std::string labelKey(const fs::path& path) { return readKey(path, ReadOptions{}); }

/// 0 stays 0; kLabelCutThroughBone stays with `keep_cut`; every other value is kLabelBone.
void normaliseLabel(std::vector<std::uint8_t>& voxels, bool keep_cut) {
  for (auto& v : voxels) v = v == 0 ? 0 : keep_cut && v == kLabelCutThroughBone ? kLabelCutThroughBone : kLabelBone;
}

}  // namespace

Label readLabel(const fs::path& input, bool keep_cut, RunMemory* memory) {
  if (!fs::is_regular_file(input)) throw InputError("label image not found: " + input.string());
  if (!isImageFile(input)) throw InputError("expected a label image (.nii.gz/.nrrd/.mha), found " + input.string());
  // A uint8 label (as articula writes them) is read as it is stored: a float
  // copy of a CT-sized label is four times the memory and time.
  if (storedComponentType(input) == itk::IOComponentEnum::UCHAR) {
    if (memory) {
      const auto kept = memory->kept<KeptLabel>("label", labelKey(input), [&] {
        return KeptLabel{readImageFile<std::uint8_t>(input).voxels};
      });
      Label label;
      label.geometry = readImageGeometry(input);
      if (static_cast<size_t>(label.geometry.voxelCount()) == kept->voxels.size()) {
        label.voxels = kept->voxels;
        normaliseLabel(label.voxels, keep_cut);
        return label;
      }
    }
    Label label = readImageFile<std::uint8_t>(input);
    checkDirection(label.geometry.direction, input.string());
    normaliseLabel(label.voxels, keep_cut);
    return label;
  }
  const Image<float> raw = readImageFile<float>(input);
  checkDirection(raw.geometry.direction, input.string());
  Label label;
  label.geometry = raw.geometry;
  label.voxels.resize(raw.voxels.size());
  for (size_t n = 0; n < raw.voxels.size(); ++n) label.voxels[n] = raw.voxels[n] > 0.5f ? kLabelBone : 0;
  return label;
}

void keepWrittenLabel(const fs::path& path, const Label& label, RunMemory* memory) {
  if (!memory) return;
  memory->kept<KeptLabel>("label", labelKey(path), [&] { return KeptLabel{label.voxels}; });
}

void writeVolume(const fs::path& path, const Volume& volume, bool overwrite) {
  Image<short> hu;
  hu.geometry = volume.geometry;
  hu.voxels.resize(volume.voxels.size());
  for (size_t n = 0; n < hu.voxels.size(); ++n)
    hu.voxels[n] = static_cast<short>(std::lround(std::clamp(volume.voxels[n], -32768.0f, 32767.0f)));
  writeImageFile(path, hu, overwrite);
}

void writeLabel(const fs::path& path, const Label& label, bool overwrite) { writeImageFile(path, label, overwrite); }

void writeDicomSeries(const fs::path& folder, const Volume& volume, const std::string& series_description) {
  using Image3 = itk::Image<short, 3>;
  using Image2 = itk::Image<short, 2>;
  Image<short> hu;
  hu.geometry = volume.geometry;
  hu.voxels.resize(volume.voxels.size());
  for (size_t n = 0; n < hu.voxels.size(); ++n)
    hu.voxels[n] = static_cast<short>(std::lround(std::clamp(volume.voxels[n], -32768.0f, 32767.0f)));
  Image3::Pointer image = toItk(hu);
  const ImageGeometry& g = volume.geometry;
  std::error_code ec;
  fs::create_directories(folder, ec);
  if (ec) throw InputError("cannot create folder " + folder.string() + ": " + ec.message());

  gdcm::UIDGenerator uids;
  const std::string study = uids.Generate(), series = uids.Generate(), frame = uids.Generate();
  std::vector<itk::MetaDataDictionary> dicts(static_cast<size_t>(g.size[2]));
  std::vector<itk::MetaDataDictionary*> dict_ptrs;
  std::vector<std::string> files;
  auto num = [](double v) {
    std::ostringstream s;
    s.precision(10);
    s << v;
    return s.str();
  };
  const Eigen::Vector3d r = g.direction.col(0), c = g.direction.col(1);
  for (int k = 0; k < g.size[2]; ++k) {
    itk::MetaDataDictionary& d = dicts[static_cast<size_t>(k)];
    const Eigen::Vector3d p = g.toPhysical(Eigen::Vector3d(0, 0, k));
    auto put = [&d](const char* tag, const std::string& v) { itk::EncapsulateMetaData<std::string>(d, tag, v); };
    put("0008|0060", "CT");
    put("0008|0016", "1.2.840.10008.5.1.4.1.1.2");
    put("0008|0018", uids.Generate());
    put("0008|103e", series_description);
    put("0010|0010", "PHANTOM^ARTICULA");
    put("0010|0020", "ARTICULA-PHANTOM");
    put("0020|000d", study);
    put("0020|000e", series);
    put("0020|0052", frame);
    put("0020|0011", "1");
    put("0020|0013", std::to_string(k + 1));
    put("0020|0032", num(p[0]) + "\\" + num(p[1]) + "\\" + num(p[2]));
    put("0020|0037", num(r[0]) + "\\" + num(r[1]) + "\\" + num(r[2]) + "\\" + num(c[0]) + "\\" + num(c[1]) + "\\" + num(c[2]));
    put("0018|0050", num(g.voxelExtent()[2]));
    put("0028|0030", num(g.spacing[1]) + "\\" + num(g.spacing[0]));  // row spacing \ column spacing
    put("0028|0004", "MONOCHROME2");
    put("0028|1052", "0");
    put("0028|1053", "1");
    dict_ptrs.push_back(&d);
    char name[32];
    std::snprintf(name, sizeof name, "slice_%04d.dcm", k);
    files.push_back((folder / name).string());
  }
  auto io = itk::GDCMImageIO::New();
  io->KeepOriginalUIDOn();
  auto writer = itk::ImageSeriesWriter<Image3, Image2>::New();
  writer->SetInput(image);
  writer->SetImageIO(io);
  writer->SetFileNames(files);
  writer->SetMetaDataDictionaryArray(&dict_ptrs);
  try {
    writer->Update();
  } catch (const itk::ExceptionObject& e) {
    throw InputError("could not write the DICOM series to " + folder.string() + ": " + e.GetDescription());
  }
}

std::string itkVersion() { return itk::Version::GetITKVersion(); }

}  // namespace articula::imaging
