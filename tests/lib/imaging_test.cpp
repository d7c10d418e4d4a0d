// Imaging: file round trips (NIfTI, DICOM) keep the physical geometry, the
// bad-input checks refuse with exit code 3, and the head segmentation of the
// phantom matches its truth; the real CTs give one plausible head.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <unistd.h>

#include <gtest/gtest.h>

#include "articula/core/error.hpp"
#include "articula/imaging/io.hpp"
#include "articula/imaging/noise.hpp"
#include "articula/imaging/segment.hpp"
#include "ct_test_support.hpp"

namespace articula {
namespace {

using imaging::ImageGeometry;
using testing::headDistance;

phantom::Phantom smallPhantom(unsigned long long seed, bool ras = false) {
  phantom::PhantomOptions o;
  o.seed = seed;
  o.spacing = Eigen::Vector3d(1.2, 1.2, 2.0);
  o.ras_storage = ras;
  return phantom::makePhantom(o);
}

void expectSameGeometry(const ImageGeometry& a, const ImageGeometry& b) {
  EXPECT_EQ(a.size, b.size);
  EXPECT_LT((a.spacing - b.spacing).cwiseAbs().maxCoeff(), 1e-4);
  EXPECT_LT((a.origin - b.origin).cwiseAbs().maxCoeff(), 1e-3);
  EXPECT_LT((a.direction - b.direction).cwiseAbs().maxCoeff(), 1e-6);
  // The same voxel lands on the same physical point.
  const Eigen::Vector3d ijk(3, 7, 5);
  EXPECT_LT((a.toPhysical(ijk) - b.toPhysical(ijk)).norm(), 1e-3);
}

TEST(ImagingIo, NiftiRoundTripKeepsLpsGeometryEvenWhenStoredRas) {
  for (bool ras : {false, true}) {
    const phantom::Phantom p = smallPhantom(2, ras);
    const auto dir = testing::scratch("nifti");
    imaging::writeVolume(dir / "ct.nii.gz", p.ct);
    imaging::ReadReport report;
    const imaging::Volume back = imaging::readVolume(dir / "ct.nii.gz", {}, &report);
    expectSameGeometry(p.ct.geometry, back.geometry);
    double worst = 0;
    for (size_t n = 0; n < back.voxels.size(); ++n) worst = std::max(worst, std::fabs(double(back.voxels[n]) - p.ct.voxels[n]));
    EXPECT_LE(worst, 0.5 + 1e-6);  // stored as int16
    std::filesystem::remove_all(dir);
  }
}

// A volume read again with a run's memory comes from memory, the same
// voxels, not a copy; other options or a file changed since (size or time)
// are read anew; without a memory every read goes to the file, and two
// memories keep their own.
TEST(ImagingIo, RunMemoryAnswersARepeatedReadUntilTheFileChanges) {
  const phantom::Phantom p = smallPhantom(5);
  const auto dir = testing::scratch("memory");
  imaging::writeVolume(dir / "ct.nii.gz", p.ct);
  RunMemory memory;
  const auto first = imaging::readSharedVolume(dir / "ct.nii.gz", {}, nullptr, &memory);
  const auto again = imaging::readSharedVolume(dir / "ct.nii.gz", {}, nullptr, &memory);
  EXPECT_EQ(memory.hits(), 1);
  EXPECT_EQ(first, again);  // the kept volume itself
  const float first_voxel = first->voxels[0];
  imaging::ReadOptions other;
  other.spacing_tolerance = 0.02;
  const auto with_other = imaging::readSharedVolume(dir / "ct.nii.gz", other, nullptr, &memory);
  EXPECT_NE(with_other, first);  // other options: another read
  EXPECT_EQ(memory.hits(), 1);
  imaging::Volume changed = p.ct;
  for (float& v : changed.voxels) v += 100;
  imaging::writeVolume(dir / "ct.nii.gz", changed);
  std::filesystem::last_write_time(dir / "ct.nii.gz", std::filesystem::last_write_time(dir / "ct.nii.gz") +
                                                          std::chrono::seconds(2));
  const auto reread = imaging::readSharedVolume(dir / "ct.nii.gz", other, nullptr, &memory);
  EXPECT_EQ(memory.hits(), 1);
  EXPECT_NEAR(reread->voxels[0], first_voxel + 100, 0.5);
  EXPECT_EQ(first->voxels[0], first_voxel);  // a volume handed out earlier stays as it was
  RunMemory fresh;
  imaging::readSharedVolume(dir / "ct.nii.gz", other, nullptr, &fresh);
  EXPECT_EQ(fresh.hits(), 0);
  const auto alone = imaging::readSharedVolume(dir / "ct.nii.gz", {}), alone_again = imaging::readSharedVolume(dir / "ct.nii.gz", {});
  EXPECT_NE(alone, alone_again);  // without a memory, each read its own
  std::filesystem::remove_all(dir);
}

// A label a run's stage wrote and kept is read back from memory as the file
// would give it: the same voxels (values normalised as from the file, the
// cut kept only when asked) and the same grid, bit for bit; once the file
// changes, it is read from the file.
TEST(ImagingIo, KeptLabelReadsAsItsFileUntilTheFileChanges) {
  const phantom::Phantom p = smallPhantom(6);
  imaging::Label label = p.femur;
  size_t marked = 0;
  for (size_t n = 0; n < label.voxels.size() && marked < 40; ++n)
    if (label.voxels[n] != 0) label.voxels[n] = marked++ % 2 ? imaging::kLabelCutThroughBone : 7;
  ASSERT_EQ(marked, 40u);
  const auto dir = testing::scratch("kept-label");
  const auto file = dir / "label.nii.gz";
  imaging::writeLabel(file, label);
  RunMemory memory;
  imaging::keepWrittenLabel(file, label, &memory);
  for (const bool keep_cut : {false, true}) {
    const long long hits = memory.hits();
    const imaging::Label kept = imaging::readLabel(file, keep_cut, &memory);
    EXPECT_EQ(memory.hits(), hits + 1);
    const imaging::Label from_file = imaging::readLabel(file, keep_cut);
    EXPECT_EQ(kept.voxels, from_file.voxels);
    EXPECT_EQ(kept.geometry.size, from_file.geometry.size);
    EXPECT_EQ(kept.geometry.spacing, from_file.geometry.spacing);
    EXPECT_EQ(kept.geometry.origin, from_file.geometry.origin);
    EXPECT_EQ(kept.geometry.direction, from_file.geometry.direction);
    EXPECT_EQ(std::count(kept.voxels.begin(), kept.voxels.end(), imaging::kLabelCutThroughBone), keep_cut ? 20 : 0);
    EXPECT_EQ(std::count(kept.voxels.begin(), kept.voxels.end(), 7), 0);
  }
  imaging::Label changed = label;
  std::fill(changed.voxels.begin(), changed.voxels.end(), 0);
  imaging::writeLabel(file, changed);
  std::filesystem::last_write_time(file, std::filesystem::last_write_time(file) + std::chrono::seconds(2));
  const long long hits = memory.hits();
  const imaging::Label reread = imaging::readLabel(file, false, &memory);
  EXPECT_EQ(memory.hits(), hits);
  EXPECT_EQ(std::count(reread.voxels.begin(), reread.voxels.end(), 0), static_cast<long>(reread.voxels.size()));
  std::filesystem::remove_all(dir);
}

TEST(ImagingIo, DicomSeriesRoundTripAndChecks) {
  const phantom::Phantom p = smallPhantom(3, true);
  const auto dir = testing::scratch("dicom");
  imaging::writeDicomSeries(dir / "series", p.ct, "test");
  imaging::ReadReport report;
  const imaging::Volume back = imaging::readVolume(dir / "series", {}, &report);
  expectSameGeometry(p.ct.geometry, back.geometry);
  EXPECT_EQ(report.source, "dicom");
  EXPECT_EQ(report.modality, "CT");
  EXPECT_NEAR(report.slice_spacing_mm, 2.0, 1e-6);
  EXPECT_LT(report.gantry_tilt_deg, 1e-3);
  EXPECT_NEAR(back.at(10, 20, 5), std::lround(p.ct.at(10, 20, 5)), 1e-3);

  // A missing slice in the middle: refused with the gap named.
  std::filesystem::remove(dir / "series" / "slice_0010.dcm");
  try {
    imaging::readVolume(dir / "series", {});
    ADD_FAILURE() << "a missing slice was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("non-uniform slice spacing"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("slice_0009.dcm"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

// Slice Thickness (0018,0050) is what a voxel averages over across the
// slices where it departs from their spacing; a thickness no reconstruction
// gives (ten times the spacing) is named in a warning and left out.
TEST(ImagingIo, DicomSliceThicknessIsTheVoxelsExtentAcrossTheSlices) {
  phantom::Phantom p = smallPhantom(3, true);
  ASSERT_NEAR(p.ct.geometry.spacing[2], 2.0, 1e-9);
  const auto dir = testing::scratch("thickness");
  const auto readWith = [&](double thickness, imaging::ReadReport& report) {
    p.ct.geometry.slice_thickness_mm = thickness;
    const auto folder = dir / ("t" + std::to_string(static_cast<int>(10 * thickness)));
    imaging::writeDicomSeries(folder, p.ct, "test");
    return imaging::readVolume(folder, {}, &report).geometry;
  };
  imaging::ReadReport report;
  const imaging::ImageGeometry thick = readWith(3.0, report);
  EXPECT_NEAR(report.slice_thickness_mm, 3.0, 1e-9);
  EXPECT_NEAR(thick.slice_thickness_mm, 3.0, 1e-9);
  EXPECT_NEAR(thick.voxelExtent()[2], 3.0, 1e-9);
  EXPECT_NEAR(thick.voxelExtent()[0], thick.spacing[0], 1e-12);
  EXPECT_TRUE(report.warnings.empty());

  const imaging::ImageGeometry plain = readWith(0.0, report);  // the writer states the spacing
  EXPECT_NEAR(report.slice_thickness_mm, 2.0, 1e-9);
  EXPECT_EQ(plain.slice_thickness_mm, 0.0);
  EXPECT_NEAR(plain.voxelExtent()[2], 2.0, 1e-9);

  const imaging::ImageGeometry absurd = readWith(20.0, report);
  EXPECT_EQ(absurd.slice_thickness_mm, 0.0);
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_NE(report.warnings[0].find("Slice Thickness (0018,0050) states 20 mm"), std::string::npos) << report.warnings[0];
  std::filesystem::remove_all(dir);
}

TEST(ImagingIo, BadFoldersAndFilesAreInputErrors) {
  const auto dir = testing::scratch("bad");
  EXPECT_THROW(imaging::readVolume(dir, {}), InputError);  // empty folder
  std::ofstream(dir / "notes.txt") << "not a DICOM file\n";
  EXPECT_THROW(imaging::readVolume(dir, {}), InputError);  // no DICOM inside
  EXPECT_THROW(imaging::readVolume(dir / "missing.nii.gz", {}), InputError);
  EXPECT_THROW(imaging::readVolume(dir / "notes.txt", {}), InputError);
  std::ofstream(dir / "broken.nii.gz") << "garbage";
  EXPECT_THROW(imaging::readVolume(dir / "broken.nii.gz", {}), InputError);
  EXPECT_THROW(imaging::checkDirection(Eigen::Matrix3d::Constant(1.0), "test"), InputError);
  std::filesystem::remove_all(dir);
}

// Found by fuzzing (fuzz/fuzz_nifti): the message of a damaged gzip stream
// was read from zlib after the stream (and the message with it) was freed.
TEST(ImagingIo, DamagedGzipStreamIsRefusedWithZlibsReason) {
  const auto dir = testing::scratch("gzip");
  imaging::Volume v;
  v.geometry.size = Eigen::Vector3i(24, 24, 24);
  v.voxels.resize(static_cast<size_t>(v.geometry.voxelCount()));
  unsigned state = 12345;  // noise, so that the stream stays long
  for (float& x : v.voxels) x = static_cast<float>((state = state * 1103515245u + 12345u) >> 20) - 2048.0f;
  imaging::writeVolume(dir / "whole.nii.gz", v);
  const std::string bytes = testsupport::readText(dir / "whole.nii.gz");
  ASSERT_GT(bytes.size(), 4000u);
  std::ofstream(dir / "cut.nii.gz", std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  try {
    imaging::readVolume(dir / "cut.nii.gz", {});
    ADD_FAILURE() << "a cut gzip stream was read";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("damaged"), std::string::npos) << m;
    EXPECT_NE(m.find("unexpected end of file"), std::string::npos) << m;
  }
  std::filesystem::remove_all(dir);
}

// A label's every value but 0 is bone, read as kLabelBone; the cut through
// bone that articula's segmentation marks keeps its value when asked.
TEST(ImagingIo, LabelValuesAreBoneUnlessTheCutIsKept) {
  const auto dir = testing::scratch("label-values");
  imaging::Label label;
  label.geometry.size = Eigen::Vector3i(4, 3, 2);
  label.voxels = {0, 1, 2, 7, 0, 2, 1, 1, 0, 0, 255, 2, 0, 1, 2, 7, 0, 2, 1, 1, 0, 0, 255, 2};
  imaging::writeLabel(dir / "label.nii.gz", label);
  const imaging::Label bone = imaging::readLabel(dir / "label.nii.gz");
  const imaging::Label kept = imaging::readLabel(dir / "label.nii.gz", true);
  ASSERT_EQ(bone.voxels.size(), label.voxels.size());
  ASSERT_EQ(kept.voxels.size(), label.voxels.size());
  for (size_t n = 0; n < label.voxels.size(); ++n) {
    const std::uint8_t v = label.voxels[n];
    EXPECT_EQ(bone.voxels[n], v == 0 ? 0 : imaging::kLabelBone) << n;
    EXPECT_EQ(kept.voxels[n], v == 0 ? 0 : v == imaging::kLabelCutThroughBone ? v : imaging::kLabelBone) << n;
  }
  std::filesystem::remove_all(dir);
}

// A NIfTI-1 header (4x4x4 int16 unless changed) and its extension bytes;
// `big` writes it big-endian.
std::string niftiHeader(bool big, std::int16_t dim0, std::int16_t nx, std::int16_t ny, std::int16_t nz,
                        const char* magic = "n+1") {
  std::string h(352, '\0');
  auto put = [&](int at, auto value) {
    unsigned char b[sizeof value];
    std::memcpy(b, &value, sizeof value);
    if (big) std::reverse(b, b + sizeof value);
    std::memcpy(&h[static_cast<size_t>(at)], b, sizeof value);
  };
  put(0, std::int32_t{348});
  const std::int16_t dims[8] = {dim0, nx, ny, nz, 1, 1, 1, 1};
  for (int i = 0; i < 8; ++i) put(40 + 2 * i, dims[i]);
  put(70, std::int16_t{4});
  put(72, std::int16_t{16});
  for (int i = 0; i < 8; ++i) put(76 + 4 * i, 1.0f);
  put(108, 352.0f);
  put(112, 1.0f);
  put(252, std::int16_t{1});  // qform_code: scanner; quaternion and offsets 0 (identity)
  std::memcpy(&h[344], magic, 4);
  return h;
}

// Found by fuzzing (fuzz/fuzz_nifti): ITK allocated the image a header
// declared before reading a voxel (a header of 2.5e8 voxels in a file of 350
// bytes took 1.5 GB): an Analyze-style .nii (no "n+1" magic) was not measured,
// nor a header whose byte order nifti1_io takes from dim[0] against its size.
TEST(ImagingIo, NiftiHeadersPromisingMoreThanTheFileHoldsAreRefused) {
  const auto dir = testing::scratch("nifti_size");
  auto refused = [&](const std::string& name, const std::string& bytes, const std::string& part) {
    std::ofstream(dir / name, std::ios::binary) << bytes;
    try {
      imaging::readVolume(dir / name, {});
      ADD_FAILURE() << name << " was read";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << name << ": " << e.what();
    }
  };
  const std::string voxels(4 * 4 * 4 * 2, '\0');
  std::string ok = voxels;
  ok[0] = 1;  // a CT whose voxels all hold one value is refused on its own
  std::ofstream(dir / "ok.nii", std::ios::binary) << niftiHeader(false, 3, 4, 4, 4) + ok;
  EXPECT_EQ(imaging::readVolume(dir / "ok.nii", {}).geometry.size, Eigen::Vector3i(4, 4, 4));
  refused("flat.nii", niftiHeader(false, 3, 4, 4, 4) + voxels, "every voxel holds the same value");

  refused("analyze.nii", niftiHeader(false, 3, 26414, 122, 77, "\0\0\0\0") + voxels, "truncated");
  // Header size 348 little-endian, dim[0] valid big-endian only: nifti1_io reads big-endian dims.
  std::string swapped = niftiHeader(true, 3, 30000, 30000, 30000);
  const std::int32_t little_size = 348;
  std::memcpy(&swapped[0], &little_size, 4);
  refused("swapped.nii", swapped + voxels, "truncated");
  refused("rank.nii", niftiHeader(false, 0, 4, 4, 4) + voxels, "dim[0]");
  // A header size of 540 without NIfTI-2's magic "n+2": nifti1_io reads it in
  // NIfTI-1's layout (11776 x 31335 voxels: 369 MB, then 1.5 GB as floats).
  std::string sized = niftiHeader(false, 3, 11776, 31335, 1, "\0\0\0\0") + std::string(200, '\0');
  const std::int32_t nifti2_size = 540;
  std::memcpy(&sized[0], &nifti2_size, 4);
  refused("sized540.nii", sized + voxels, "truncated");
  // With NIfTI-2's magic as well (fuzz/fuzz_nifti's find): ITK 5.2 reads
  // NIfTI-1 only and took it for that 1.5 GB Analyze image.
  std::memcpy(&sized[4], "n+2\0", 4);
  const std::string itk = imaging::itkVersion();
  if (itk.rfind("4.", 0) == 0 || itk.rfind("5.0", 0) == 0 || itk.rfind("5.1", 0) == 0 || itk.rfind("5.2", 0) == 0)
    refused("nifti2.nii", sized + voxels, "NIfTI-2");
  std::filesystem::remove_all(dir);
}

struct HeadCheck {
  double head_recall;     // fraction of voxels 1 voxel inside the true head (off the neck) labelled
  double socket_leak;     // fraction of labelled voxels farther than gap/2 outside the head
  double center_error_mm; // deepest label point vs true centre
};

HeadCheck checkHead(const phantom::Phantom& p, const imaging::Label& label, const imaging::SegmentSummary& s) {
  const auto head = geometry::makeSurface(p.head);
  const ImageGeometry& g = p.ct.geometry;
  const double voxel = g.spacing.maxCoeff();
  long long inside = 0, inside_hit = 0, labelled = 0, leak = 0;
  const double gap = p.truth["joint_gap_mm"].get<double>();
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = 0; i < g.size[0]; ++i) {
        const Eigen::Vector3d x = g.toPhysical(Eigen::Vector3d(i, j, k));
        if ((x - p.head.center).norm() > 45) continue;
        const double d = headDistance(*head, x);
        const bool l = label.at(i, j, k) != 0;
        // Recall over the articular part: away from the neck, where the cut lies.
        if (d < -voxel && (x - p.head.center).normalized().dot(p.neck_axis) < 0.3) inside++, inside_hit += l;
        if (l) {
          labelled++;
          // Outside the head and not in the femur (neck): the socket side.
          if (d > gap / 2 && !p.femur.at(i, j, k)) leak++;
        }
      }
  return {double(inside_hit) / std::max<long long>(inside, 1), double(leak) / std::max<long long>(labelled, 1),
          (s.head_center_mm - p.head.center).norm()};
}

// Segments the phantom's CT as `articula segment` would (its summary into
// `s`) and checks the label against the phantom's truth.
HeadCheck segmentAndCheck(const phantom::Phantom& p, const imaging::SegmentOptions& so, imaging::SegmentSummary& s) {
  const imaging::Label label = imaging::segmentHead(p.ct, so, &s);
  return checkHead(p, label, s);
}

HeadCheck segmentLeftAndCheck(const phantom::Phantom& p, imaging::SegmentSummary& s) {
  imaging::SegmentOptions so;
  so.side = imaging::Side::Left;
  return segmentAndCheck(p, so, s);
}

TEST(ImagingSegment, PhantomHeadMatchesTruthAcrossGapsSidesAndSpacings) {
  struct Case { double gap; bool right; Eigen::Vector3d spacing; };
  for (const Case& c : {Case{2.0, true, {0.7, 0.7, 1.5}}, Case{4.0, false, {0.7, 0.7, 1.5}},
                       Case{3.0, true, {1.0, 1.0, 2.0}}}) {
    phantom::PhantomOptions o;
    o.seed = 7;
    o.model = geometry::ShapeModel::Ellipsoid;
    o.gap_mm = c.gap;
    o.right = c.right;
    o.spacing = c.spacing;
    const phantom::Phantom p = phantom::makePhantom(o);
    imaging::SegmentOptions so;
    so.side = c.right ? imaging::Side::Right : imaging::Side::Left;
    imaging::SegmentSummary s;
    const HeadCheck h = segmentAndCheck(p, so, s);
    SCOPED_TRACE("gap " + std::to_string(c.gap) + (c.right ? " right" : " left"));
    EXPECT_GT(h.head_recall, 0.97);
    EXPECT_LT(h.socket_leak, 0.01);
    // The search's sphere, fitted to an ellipsoid's visible cap: near its
    // centre (not on it), its radius within the ellipsoid's.
    EXPECT_LT(h.center_error_mm, 2.5);
    EXPECT_GT(s.search_radius_mm, p.head.radii.minCoeff() - 1.0);
    EXPECT_LT(s.search_radius_mm, p.head.radii.maxCoeff() + 1.0);
    EXPECT_GT(s.head_depth_mm, 0.8 * p.head.radii.minCoeff());
  }
}

// The phantom's CT cut to a field of view centred (left-right) on its head,
// `half_width_mm` either side, as a scanner's targeted reconstruction of one hip.
imaging::Volume centredOnHead(const phantom::Phantom& p, double half_width_mm) {
  const ImageGeometry& g = p.ct.geometry;
  const Eigen::Vector3d c = g.toIndex(p.head.center);
  const int half = static_cast<int>(half_width_mm / g.spacing[0]);
  const int i0 = std::max(0, static_cast<int>(std::lround(c[0])) - half);
  const int i1 = std::min(g.size[0] - 1, static_cast<int>(std::lround(c[0])) + half);
  imaging::Volume out;
  out.geometry = g;
  out.geometry.size[0] = i1 - i0 + 1;
  out.geometry.origin = g.toPhysical(Eigen::Vector3d(i0, 0, 0));
  out.voxels.resize(static_cast<size_t>(out.geometry.voxelCount()));
  for (int k = 0; k < g.size[2]; ++k)
    for (int j = 0; j < g.size[1]; ++j)
      for (int i = i0; i <= i1; ++i) out.at(i - i0, j, k) = p.ct.at(i, j, k);
  return out;
}

TEST(ImagingSegment, AFieldOfViewCentredOnTheHeadTellsTheSideByTheSocket) {
  // The field's middle is the head's own x: no side can be read from
  // positions, and the body's outline is not in the field. The socket,
  // medial across the joint space, tells it: the head is found on its side
  // and refused, naming the side it is, on the other.
  for (const bool right : {true, false}) {
    phantom::PhantomOptions o;
    o.seed = 11;
    o.right = right;
    o.spacing = Eigen::Vector3d(0.8, 0.8, 1.0);
    phantom::Phantom p = phantom::makePhantom(o);
    p.ct = centredOnHead(p, 60);
    const ImageGeometry& g = p.ct.geometry;
    EXPECT_NEAR(g.toPhysical((g.size.cast<double>() - Eigen::Vector3d::Ones()) / 2)[0], p.head.center[0], 1.0);
    imaging::SegmentOptions so;
    so.side = right ? imaging::Side::Right : imaging::Side::Left;
    imaging::SegmentSummary s;
    const imaging::Label label = imaging::segmentHead(p.ct, so, &s);
    SCOPED_TRACE(right ? "right" : "left");
    EXPECT_GT(s.label_voxels, 0.9 * 4.0 / 3.0 * M_PI * p.head.radii.prod() / g.spacing.prod());  // the whole head
    EXPECT_EQ(label.geometry.size, g.size);
    EXPECT_NE(s.side_check.find("socket lies medially"), std::string::npos) << s.side_check;
    EXPECT_LT((s.head_center_mm - p.head.center).norm(), 2.5);
    imaging::SegmentOptions other = so;
    other.side = right ? imaging::Side::Left : imaging::Side::Right;
    try {
      imaging::segmentHead(p.ct, other);
      ADD_FAILURE() << "the other side was not refused";
    } catch (const ProcessingError& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("the joint in view is a ") + (right ? "right" : "left")), std::string::npos)
          << e.what();
    }
  }
}

TEST(ImagingSegment, ACandidateMeasuredFromNearItsEdgeKeepsTheHeadsRim) {
  // A small osteoporotic head (seed 11, 0.8 mm voxels) where one Hough peak
  // lies 17 mm above the centre: its rays find a small sphere first and
  // reach the head only after several rounds. Measured from where its rays
  // did not start, its edges sat 2 mm inside the head and the cut took the
  // head's rim off (points 0.9 mm inside the true surface); a candidate is
  // now measured only once its centre settles.
  phantom::PhantomOptions o;
  o.seed = 11;
  o.model = geometry::ShapeModel::Sphere;
  o.spacing = Eigen::Vector3d(0.8, 0.8, 0.8);
  o.gap_mm = 4.0;
  o.head_radius_mm = 17.4;
  o.fovea = true;
  o.exact_depth = true;
  o.ras_storage = true;
  o.makeOsteoporotic();
  phantom::Phantom p = phantom::makePhantom(o);
  // As `articula phantom` stores it (NIfTI, int16) and the run reads it.
  const auto dir = testing::scratch("near-edge");
  imaging::writeVolume(dir / "ct.nii.gz", p.ct);
  p.ct = imaging::readVolume(dir / "ct.nii.gz", {});
  imaging::SegmentSummary s;
  const HeadCheck h = segmentAndCheck(p, {}, s);
  EXPECT_GT(h.head_recall, 0.97);
  EXPECT_LT(h.socket_leak, 0.01);
  EXPECT_LT(h.center_error_mm, 1.0);
  std::filesystem::remove_all(dir);
}

// A head of the clinical bench (bench/clinical.py's HEADS): its seed,
// model, mean radius, side, voxels and joint gap, at exact widths.
phantom::PhantomOptions clinicalHead(unsigned long long seed, geometry::ShapeModel model, double radius_mm, bool right,
                                     const Eigen::Vector3d& spacing, double gap_mm) {
  phantom::PhantomOptions o;
  o.seed = seed;
  o.model = model;
  o.head_radius_mm = radius_mm;
  o.right = right;
  o.spacing = spacing;
  o.gap_mm = gap_mm;
  o.exact_depth = true;
  return o;
}

TEST(ImagingSegment, ALagScrewsStreaksInsideTheHeadDoNotHideIt) {
  // A lag screw along the neck into the head (0.9 x 0.9 x 2.5 mm voxels):
  // its dark streaks, radial from the screw and so from the head's centre,
  // end the rays along them 6-14 mm out, on more rays than reach the
  // surface. The median edge then lay among them, the head's candidates
  // never settled, and the search took the greater trochanter, 42 mm off.
  // The sphere a quarter of the rays further out, on which many more rays
  // agree, is now taken.
  phantom::PhantomOptions o =
      clinicalHead(305, geometry::ShapeModel::Superovoid, 20, true, Eigen::Vector3d(0.9, 0.9, 2.5), 2.0);
  o.metal = phantom::PhantomOptions::Metal::Screw;
  phantom::Phantom p = phantom::makePhantom(o);
  const auto dir = testing::scratch("lag-screw");
  imaging::writeVolume(dir / "ct.nii.gz", p.ct);  // int16, as `articula phantom` stores it
  p.ct = imaging::readVolume(dir / "ct.nii.gz", {});
  imaging::SegmentSummary s;
  const HeadCheck h = segmentAndCheck(p, {}, s);
  EXPECT_EQ(s.head_found_by, "edges");
  EXPECT_LT(h.center_error_mm, 1.5);
  EXPECT_NEAR(s.search_radius_mm, p.head.radii.mean(), 1.5);
  EXPECT_GT(h.head_recall, 0.9);
  std::filesystem::remove_all(dir);
}

TEST(ImagingSegment, LowDoseNoiseClosedAroundTheHeadIsCutOff) {
  // Noise of 100 HU (a low-dose scan): the HU window and the closing make
  // the soft tissue about the head bone, so the shell the cut beyond the
  // head's edges opens was a hole of the mask, and filling the holes gave
  // it back: the label reached the watershed's outer marker (1.35 radii) in
  // every direction, and the fit's radius came out 16-22 % large.
  phantom::PhantomOptions o =
      clinicalHead(302, geometry::ShapeModel::Ellipsoid, 22, false, Eigen::Vector3d(0.8, 0.8, 1.5), 2.5);
  o.noise_hu = 100;
  const phantom::Phantom p = phantom::makePhantom(o);
  imaging::SegmentSummary s;
  const HeadCheck h = segmentLeftAndCheck(p, s);
  EXPECT_EQ(s.head_found_by, "edges");
  EXPECT_GT(h.head_recall, 0.95);
  EXPECT_LT(h.socket_leak, 0.02);
  EXPECT_LT(s.label_voxels * p.ct.geometry.spacing.prod(), 1.6 * 4.0 / 3.0 * M_PI * p.head.radii.prod());
}

TEST(ImagingSegment, AFlattenedDomesGapToTheSocketIsCutOff) {
  // A dome flattened by a quarter of the radius (4.5 mm; 0.6 x 0.6 x 1 mm
  // voxels): the rays' edges on the flat lie below the sphere's band, so
  // the cap's edges had a hole there too wide for the rings that fill a
  // missed edge; no cut was made over it, the closing's bridge across the
  // widened gap stayed, and the label ran on into the socket (the mesh then
  // showed an outward bump of 5.6 mm over 347 mm^2 beside the flat).
  phantom::PhantomOptions o =
      clinicalHead(301, geometry::ShapeModel::Sphere, 18, true, Eigen::Vector3d(0.6, 0.6, 1.0), 3.0);
  o.flattened_dome = 0.25;
  const phantom::Phantom p = phantom::makePhantom(o);
  imaging::SegmentSummary s;
  const HeadCheck h = segmentAndCheck(p, {}, s);
  EXPECT_EQ(s.head_found_by, "edges");
  EXPECT_GT(h.head_recall, 0.95);
  EXPECT_LT(h.socket_leak, 0.005);  // 0.027 before
}

TEST(ImagingSegment, AFaintHeadsSocketAcrossANarrowGapIsCutOffAtFineSlices) {
  // Osteoporotic bone (a cortex of 0.8 mm at 700 HU over 190 HU) across
  // gaps of 1.2 and 1 mm at fine voxels: the gap's blurred valley falls
  // 100-160 HU from the head's cortex, short of an edge's 150 HU on many
  // rays, whose first edge is then the socket cortex's far side. The edges'
  // sphere ran between the two (0.85 mm large, its centre 1.6 mm off), and
  // the label kept the socket's cortex: 10-11 % of its voxels more than half
  // the gap outside the head. The valleys' sphere is the head's: 0.2 mm off,
  // under 1 % outside.
  struct Case { double gap_mm; Eigen::Vector3d spacing; };
  for (const Case& c : {Case{1.2, {0.7, 0.7, 0.9}}, Case{1.0, {0.6, 0.6, 0.6}}}) {
    phantom::PhantomOptions o = clinicalHead(5, geometry::ShapeModel::Sphere, 24, true, c.spacing, c.gap_mm);
    o.makeOsteoporotic();
    const phantom::Phantom p = phantom::makePhantom(o);
    imaging::SegmentSummary s;
    const HeadCheck h = segmentAndCheck(p, {}, s);
    SCOPED_TRACE("gap " + std::to_string(c.gap_mm));
    EXPECT_EQ(s.head_found_by, "edges");
    EXPECT_LT(h.center_error_mm, 0.5);
    EXPECT_NEAR(s.search_radius_mm, p.head.radii.mean(), 0.4);
    EXPECT_GT(h.head_recall, 0.95);
    EXPECT_LT(h.socket_leak, 0.02);
  }
}

TEST(ImagingSegment, ANoisySharpKernelScanIsSegmentedOnASmoothedCopy) {
  // A sharp kernel over 100 HU of noise (about 150 HU voxel to voxel): falls
  // of an edge's size lie all through the cancellous bone, every ray of the
  // head search stopped on one, and no head was found (the candidates'
  // spheres 8-9 mm across). Smoothed by an in-plane voxel, the head is
  // found and labelled as at low noise.
  phantom::PhantomOptions o = clinicalHead(5, geometry::ShapeModel::Sphere, 24, false, {0.8, 0.8, 0.8}, 3.0);
  o.kernel = phantom::PhantomOptions::Kernel::Sharp;
  o.noise_hu = 100;
  const phantom::Phantom p = phantom::makePhantom(o);
  imaging::SegmentSummary s;
  const HeadCheck h = segmentLeftAndCheck(p, s);
  EXPECT_GT(s.noise_hu, imaging::kSmoothSegmentationAboveNoiseHu);
  EXPECT_NEAR(s.smoothed_sigma_mm, 0.8, 1e-6);
  EXPECT_EQ(s.head_found_by, "edges");
  EXPECT_LT(h.center_error_mm, 0.5);
  EXPECT_NEAR(s.search_radius_mm, p.head.radii.mean(), 0.5);
  EXPECT_GT(h.head_recall, 0.95);
  EXPECT_LT(h.socket_leak, 0.02);
}

TEST(ImagingSegment, SeedPointAndFailures) {
  const phantom::Phantom p = smallPhantom(4);
  imaging::SegmentOptions so;
  so.seed_point = p.head.center;
  imaging::SegmentSummary s;
  const imaging::Label label = imaging::segmentHead(p.ct, so, &s);
  EXPECT_EQ(s.seed_source, "seed-point");
  EXPECT_GT(checkHead(p, label, s).head_recall, 0.95);
  // A window no voxel falls in: invalid input (exit 3).
  so.hu_min = 5000;
  so.hu_max = 6000;
  EXPECT_THROW(imaging::segmentHead(p.ct, so), InputError);
  // The wrong side holds no head: processing failed (exit 1).
  imaging::SegmentOptions left;
  left.side = imaging::Side::Left;
  left.min_head_radius_mm = 30;
  EXPECT_THROW(imaging::segmentHead(p.ct, left), ProcessingError);
}

TEST(ImagingRealData, RealSeriesReadWithLpsGeometry) {
  const auto hip = testing::sharedData() / "ct/hip-3mm-nifti/example_ct.nii.gz";
  const auto thorax = testing::sharedData() / "ct/thorax-shoulders-dicom";
  const auto abdomen = testing::sharedData() / "ct/abdomen-j2k-dicom";
  if (!std::filesystem::exists(hip) || !std::filesystem::exists(thorax)) GTEST_SKIP() << "no shared CT data";
  const imaging::Volume h = imaging::readVolume(hip, {});
  EXPECT_EQ(h.geometry.size, Eigen::Vector3i(122, 101, 112));
  EXPECT_LT((h.geometry.direction - Eigen::Vector3d(-1, -1, 1).asDiagonal().toDenseMatrix()).norm(), 1e-6);
  imaging::ReadReport report;
  const imaging::Volume t = imaging::readVolume(thorax, {}, &report);
  EXPECT_EQ(t.geometry.size, Eigen::Vector3i(512, 512, 141));
  EXPECT_NEAR(report.slice_spacing_mm, 2.0, 0.01);
  EXPECT_EQ(report.modality, "CT");
  if (std::filesystem::exists(abdomen)) {
    // Lossless JPEG 2000, 2 mm apart although SliceThickness says 3.
    const imaging::Volume a = imaging::readVolume(abdomen, {}, &report);
    EXPECT_EQ(a.geometry.size[2], 20);
    EXPECT_NEAR(a.geometry.spacing[2], 2.0, 0.01);
  }
}

// The automatic search on the real 3 mm hip: both femoral heads (the left
// one beside metal screws) are found as spheres of an adult head's radius,
// on their own sides and about mirror images of each other.
TEST(ImagingRealData, BothFemoralHeadsOfTheRealHipAreFound) {
  const auto hip = testing::sharedData() / "ct/hip-3mm-nifti/example_ct.nii.gz";
  if (!std::filesystem::exists(hip)) GTEST_SKIP() << "no shared CT data";
  const imaging::Volume ct = imaging::readVolume(hip, {});
  Eigen::Vector3d centers[2];
  for (int side = 0; side < 2; ++side) {
    imaging::SegmentOptions so;
    so.side = side == 0 ? imaging::Side::Right : imaging::Side::Left;
    imaging::SegmentSummary s;
    const imaging::Label label = imaging::segmentHead(ct, so, &s);
    SCOPED_TRACE(side == 0 ? "right" : "left");
    EXPECT_GT(s.search_radius_mm, 18.0);
    EXPECT_LT(s.search_radius_mm, 28.0);
    EXPECT_GT(s.head_depth_mm, 0.5 * so.min_head_radius_mm);
    EXPECT_TRUE(s.warnings.empty());
    EXPECT_GT(s.label_voxels, 1000);
    centers[side] = s.head_center_mm;
  }
  EXPECT_LT(centers[0][0], -60.0);  // patient right is -x in LPS
  EXPECT_GT(centers[1][0], 60.0);
  EXPECT_LT(std::abs(centers[0][0] + centers[1][0]), 15.0);
  EXPECT_LT((centers[0] - centers[1]).tail<2>().norm(), 12.0);
}

}  // namespace
}  // namespace articula
