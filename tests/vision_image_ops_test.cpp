// Seed 001's image operations (controller/boundary/vision/image_ops.h): ExG
// (Eq. 15), Otsu (Eq. 16) on hand-built bimodal value sets, the homography
// fit, point undistortion and the ROI warp (OpenCV behind the interface),
// each held against an independent computation: rig::camera's lens model, a
// direct evaluation of Otsu's criterion, a linear ramp's exact values.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>
#include <stdexcept>
#include <string>

#include "controller/boundary/vision/image_ops.h"

namespace {

using namespace rig::controller::boundary::vision;
using rig::camera::Rgb;

// The values a histogram counts, in order: what a frame of them would hold.
std::vector<std::uint8_t> values_of(const std::array<std::uint64_t, 256>& histogram) {
    std::vector<std::uint8_t> values;
    for (int v = 0; v < 256; ++v) values.insert(values.end(), histogram[static_cast<std::size_t>(v)], static_cast<std::uint8_t>(v));
    return values;
}

TEST(ExcessGreen, IsTwoGreenLessRedAndBlueClipped) {
    EXPECT_EQ(excess_green(Rgb{64, 128, 40}), 152);   // 256 - 64 - 40
    EXPECT_EQ(excess_green(Rgb{128, 102, 80}), 0);    // 204 - 208 = -4: clipped (S7)
    EXPECT_EQ(excess_green(Rgb{0, 255, 0}), 255);     // 510: clipped
    EXPECT_EQ(excess_green(Rgb{100, 100, 100}), 0);   // grey
    EXPECT_EQ(excess_green(Rgb{10, 60, 20}), 90);
}

TEST(ExcessGreen, ValuesOfAFrameRowByRow) {
    rig::camera::RgbImage frame(2, 2);
    frame.set(0, 0, Rgb{64, 128, 40});
    frame.set(1, 0, Rgb{0, 255, 0});
    frame.set(0, 1, Rgb{10, 60, 20});
    frame.set(1, 1, Rgb{100, 100, 100});
    EXPECT_EQ(excess_green_values(frame), (std::vector<std::uint8_t>{152, 255, 90, 0}));
}

TEST(Otsu, SplitsTwoSpikesMidwayInTheGap) {
    // 700 values at 10, 300 at 200: every T in 11..200 separates them with the
    // same between-class variance; the middle of that run is (11 + 200) / 2 = 105.
    std::array<std::uint64_t, 256> histogram{};
    histogram[10] = 700;
    histogram[200] = 300;
    EXPECT_EQ(otsu_threshold(values_of(histogram)), 105);
}

TEST(Otsu, SplitsTwoBroadModesInTheirValley) {
    // Two triangles of width 41: around 50 (weight 3) and around 170 (weight 1).
    // The valley runs 71..149 (empty): the threshold lies in it, past the
    // lower mode's last value (70) and at or before the upper's first (150).
    std::array<std::uint64_t, 256> histogram{};
    for (int d = -20; d <= 20; ++d) {
        histogram[static_cast<std::size_t>(50 + d)] = static_cast<std::uint64_t>(3 * (21 - std::abs(d)));
        histogram[static_cast<std::size_t>(170 + d)] = static_cast<std::uint64_t>(21 - std::abs(d));
    }
    const auto threshold = otsu_threshold(values_of(histogram));
    ASSERT_TRUE(threshold.has_value());
    EXPECT_GT(*threshold, 70);
    EXPECT_LE(*threshold, 150);
    EXPECT_EQ(*threshold, (71 + 150) / 2);
}

TEST(Otsu, MatchesBruteForceOnAnUnevenHistogram) {
    // Overlapping modes: no plateau, the maximiser checked against a direct
    // evaluation of w0 w1 (m0 - m1)^2 for every T.
    std::array<std::uint64_t, 256> histogram{};
    for (int v = 0; v < 256; ++v) {
        const double a = 1000.0 * std::exp(-0.5 * std::pow((v - 60) / 25.0, 2));
        const double b = 400.0 * std::exp(-0.5 * std::pow((v - 140) / 30.0, 2));
        histogram[static_cast<std::size_t>(v)] = static_cast<std::uint64_t>(a + b);
    }
    int best_t = -1;
    double best = -1.0;
    for (int t = 1; t < 256; ++t) {
        double n0 = 0, s0 = 0, n1 = 0, s1 = 0;
        for (int v = 0; v < 256; ++v) {
            const double count = static_cast<double>(histogram[static_cast<std::size_t>(v)]);
            if (v < t) {
                n0 += count;
                s0 += v * count;
            } else {
                n1 += count;
                s1 += v * count;
            }
        }
        if (n0 == 0 || n1 == 0) continue;
        const double between = n0 * n1 * std::pow(s0 / n0 - s1 / n1, 2);
        if (between > best) {
            best = between;
            best_t = t;
        }
    }
    EXPECT_EQ(otsu_threshold(values_of(histogram)), best_t);
    EXPECT_GT(best_t, 60);
    EXPECT_LT(best_t, 140);
}

TEST(Otsu, NoSplitWithoutTwoValues) {
    EXPECT_FALSE(otsu_threshold({}).has_value());
    const std::vector<std::uint8_t> bare_soil(5000, 0);  // all ExG clipped to 0: Otsu has nothing to split
    EXPECT_FALSE(otsu_threshold(bare_soil).has_value());
    std::vector<std::uint8_t> one_leaf = bare_soil;
    one_leaf.back() = 150;
    EXPECT_EQ(otsu_threshold(one_leaf), (1 + 150) / 2);  // the lone leaf value is the upper class, the gap 1..150
}

TEST(FitHomography, MapsTheFourCornersOfARoiAndKeepsIncidence) {
    const std::vector<Eigen::Vector2d> rectangle{Eigen::Vector2d(0, 200), Eigen::Vector2d(300, 200), Eigen::Vector2d(300, 0),
                                                 Eigen::Vector2d(0, 0)};
    const std::vector<Eigen::Vector2d> trapezoid{Eigen::Vector2d(399, 573), Eigen::Vector2d(761, 573), Eigen::Vector2d(748, 355),
                                                 Eigen::Vector2d(423, 355)};
    const Eigen::Matrix3d m = fit_homography(rectangle, trapezoid);
    auto apply = [&](Eigen::Vector2d p) {
        const Eigen::Vector3d h = m * Eigen::Vector3d(p.x(), p.y(), 1.0);
        return Eigen::Vector2d(h.x() / h.z(), h.y() / h.z());
    };
    for (std::size_t i = 0; i < 4; ++i) EXPECT_NEAR((apply(rectangle[i]) - trapezoid[i]).norm(), 0.0, 1e-6);
    // The rectangle's centre goes to the crossing of the trapezoid's diagonals
    // (a projective map keeps lines and incidence).
    const Eigen::Vector2d centre = apply(Eigen::Vector2d(150, 100));
    const Eigen::Vector2d d1 = trapezoid[2] - trapezoid[0];
    const Eigen::Vector2d d2 = trapezoid[3] - trapezoid[1];
    const Eigen::Vector2d c0 = centre - trapezoid[0];
    const Eigen::Vector2d c1 = centre - trapezoid[1];
    EXPECT_NEAR(d1.x() * c0.y() - d1.y() * c0.x(), 0.0, 1e-4);
    EXPECT_NEAR(d2.x() * c1.y() - d2.y() * c1.x(), 0.0, 1e-4);
    const std::vector<Eigen::Vector2d> collinear{Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 1), Eigen::Vector2d(2, 2), Eigen::Vector2d(3, 3)};
    EXPECT_THROW(fit_homography(collinear, trapezoid), std::invalid_argument);
    const std::vector<Eigen::Vector2d> repeated(4, Eigen::Vector2d(5, 5));
    EXPECT_THROW(fit_homography(rectangle, repeated), std::invalid_argument);
}

TEST(UndistortPixels, InvertsTheLensOfRigCamera) {
    // rig::camera's Brown-Conrady forward model puts each ray's pinhole pixel
    // somewhere in the frame; undistort_pixels (OpenCV) must bring it back.
    const rig::camera::PinholeCamera camera(rig::camera::seed001_boom_camera(false));
    std::vector<Eigen::Vector2d> seen;
    std::vector<Eigen::Vector2d> pinhole;
    for (const Eigen::Vector2d& normalized : {Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(-0.68, -0.38), Eigen::Vector2d(0.69, 0.39),
                                               Eigen::Vector2d(0.3, -0.2), Eigen::Vector2d(-0.7, 0.1)}) {
        seen.push_back(camera.normalized_to_pixel(normalized));
        pinhole.push_back(camera.undistorted_pixel(normalized));
    }
    const std::vector<Eigen::Vector2d> undistorted = undistort_pixels(seen, camera.model().intrinsics, camera.model().distortion);
    ASSERT_EQ(undistorted.size(), seen.size());
    for (std::size_t i = 0; i < seen.size(); ++i) EXPECT_NEAR((undistorted[i] - pinhole[i]).norm(), 0.0, 1e-4) << i;
    // The corners are where the lens moves pixels most: several px here, so
    // a missing undistortion could not pass the check above.
    EXPECT_GT((seen[1] - pinhole[1]).norm(), 5.0);
    EXPECT_TRUE(undistort_pixels({}, camera.model().intrinsics, camera.model().distortion).empty());
}

// A 64 x 48 frame without lens distortion whose red rises 3 DN per pixel to
// the right and green 4 DN per pixel down: bilinear sampling of it is exact.
rig::camera::CameraIntrinsics small_intrinsics() {
    return {.width_px = 64, .height_px = 48, .fx_px = 60.0, .fy_px = 60.0, .cx_px = 32.0, .cy_px = 24.0};
}
rig::camera::RgbImage ramp_frame() {
    rig::camera::RgbImage frame(64, 48);
    for (int v = 0; v < 48; ++v) {
        for (int u = 0; u < 64; ++u) frame.set(u, v, Rgb{static_cast<std::uint8_t>(3 * u), static_cast<std::uint8_t>(4 * v), 7});
    }
    return frame;
}

TEST(WarpToRectangle, SamplesTheQuadrilateralBilinearly) {
    // Rectangle point (x, y) -> frame (2 x + 10.25, y + 5.5): pixel (i, j)'s
    // centre (i + 0.5, j + 0.5) lands on (2 i + 11.25, j + 6), between pixel
    // centres, where the ramp reads red 3 (2 i + 10.75), green 4 (j + 5.5).
    Eigen::Matrix3d h;
    h << 2.0, 0.0, 10.25, 0.0, 1.0, 5.5, 0.0, 0.0, 1.0;
    const RectangleWarp warp = warp_to_rectangle(ramp_frame(), small_intrinsics(), rig::camera::BrownConradyDistortion{0, 0, 0, 0, 0}, h, 20, 30);
    ASSERT_EQ(warp.image.width, 20);
    ASSERT_EQ(warp.image.height, 30);
    EXPECT_EQ(warp.inside_px, 20 * 30);
    for (int j = 0; j < 30; ++j) {
        for (int i = 0; i < 20; ++i) {
            const Rgb got = warp.image.at(i, j);
            // Fixed-point weights (1/32 px, 15 bits) round to the nearest DN.
            EXPECT_NEAR(got.r, 3.0 * (2 * i + 10.75), 0.5 + 1e-9) << i << ", " << j;
            EXPECT_NEAR(got.g, 4.0 * (j + 5.5), 0.5 + 1e-9) << i << ", " << j;
            EXPECT_EQ(got.b, 7);
        }
    }
}

TEST(WarpToRectangle, CountsAndBlanksWhatFallsOutsideTheFrame) {
    // Rectangle x -> frame x + 50: columns whose centres land beyond the last
    // pixel centre (63.5) are outside: i + 50.5 > 63.5 for i >= 14.
    Eigen::Matrix3d h;
    h << 1.0, 0.0, 50.0, 0.0, 1.0, 10.0, 0.0, 0.0, 1.0;
    const RectangleWarp warp = warp_to_rectangle(ramp_frame(), small_intrinsics(), rig::camera::BrownConradyDistortion{0, 0, 0, 0, 0}, h, 20, 4);
    EXPECT_EQ(warp.inside_px, 14 * 4);
    for (int j = 0; j < 4; ++j) {
        for (int i = 0; i < 20; ++i) {
            EXPECT_EQ(warp.inside[static_cast<std::size_t>(j * 20 + i)], i < 14 ? 1 : 0) << i;
            EXPECT_EQ(warp.image.at(i, j).b, i < 14 ? 7 : 0) << i;
        }
    }
}

TEST(WarpToRectangle, UndoesTheLensAsRigCameraModelsIt) {
    // Dark frames of the seed-001 camera with one bright pixel where
    // rig::camera's lens puts a chosen undistorted point: the warp of an
    // identity rectangle (rectangle point = undistorted pixel) must show it
    // back at that point. The lens moves these points by several px (checked),
    // so a warp that ignored it, or bent it the wrong way, would fail.
    const rig::camera::PinholeCamera camera(rig::camera::seed001_boom_camera(false));
    const rig::camera::CameraIntrinsics& k = camera.model().intrinsics;
    for (const auto& [i, j] : std::vector<std::pair<int, int>>{{100, 80}, {1180, 70}, {90, 650}, {1190, 640}, {640, 360}}) {
        const Eigen::Vector2d undistorted(i + 0.5, j + 0.5);
        const Eigen::Vector2d seen = camera.normalized_to_pixel(Eigen::Vector2d((undistorted.x() - k.cx_px) / k.fx_px, (undistorted.y() - k.cy_px) / k.fy_px));
        rig::camera::RgbImage frame(k.width_px, k.height_px);
        frame.set(static_cast<int>(seen.x()), static_cast<int>(seen.y()), Rgb{255, 255, 255});
        const RectangleWarp warp = warp_to_rectangle(frame, k, camera.model().distortion, Eigen::Matrix3d::Identity(), k.width_px, k.height_px);
        int brightest = -1;
        Eigen::Vector2d found;
        for (int v = std::max(0, j - 20); v < std::min(k.height_px, j + 20); ++v) {
            for (int u = std::max(0, i - 20); u < std::min(k.width_px, i + 20); ++u) {
                if (warp.image.at(u, v).r > brightest) {
                    brightest = warp.image.at(u, v).r;
                    found = Eigen::Vector2d(u + 0.5, v + 0.5);
                }
            }
        }
        EXPECT_GT(brightest, 60) << i << ", " << j;
        EXPECT_LE((found - undistorted).norm(), 1.5) << i << ", " << j << ": found at " << found.transpose();
        if (i != 640) {
            EXPECT_GT((seen - undistorted).norm(), 5.0) << i << ", " << j;
        }
    }
}

TEST(WarpToRectangle, RefusesAFrameOfAnotherSizeOrAnEmptyRectangle) {
    const rig::camera::RgbImage wrong(32, 48);
    try {
        warp_to_rectangle(wrong, small_intrinsics(), {}, Eigen::Matrix3d::Identity(), 4, 4);
        ADD_FAILURE() << "no throw";
    } catch (const std::invalid_argument& error) {
        EXPECT_NE(std::string(error.what()).find("32 x 48"), std::string::npos) << error.what();
    }
    EXPECT_THROW(warp_to_rectangle(ramp_frame(), small_intrinsics(), {}, Eigen::Matrix3d::Identity(), 0, 4), std::invalid_argument);
    EXPECT_THROW(warp_to_rectangle(ramp_frame(), small_intrinsics(), {}, Eigen::Matrix3d::Zero(), 4, 4), std::invalid_argument);
}

}  // namespace
