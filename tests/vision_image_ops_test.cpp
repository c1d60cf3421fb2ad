// Seed 001's image operations (controller/boundary/vision/image_ops.h): ExG
// (Eq. 15), Otsu (Eq. 16) on hand-built histograms, the perspective transform
// and bilinear sampling.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "controller/boundary/vision/image_ops.h"

namespace {

using namespace rig::controller::boundary::vision;
using rig::camera::Rgb;

TEST(ExcessGreen, IsTwoGreenLessRedAndBlueClipped) {
    EXPECT_EQ(excess_green(Rgb{64, 128, 40}), 152);   // 256 - 64 - 40
    EXPECT_EQ(excess_green(Rgb{128, 102, 80}), 0);    // 204 - 208 = -4: clipped (S7)
    EXPECT_EQ(excess_green(Rgb{0, 255, 0}), 255);     // 510: clipped
    EXPECT_EQ(excess_green(Rgb{100, 100, 100}), 0);   // grey
    EXPECT_EQ(excess_green(Rgb{10, 60, 20}), 90);
}

TEST(Otsu, SplitsTwoSpikesMidwayInTheGap) {
    // 700 pixels at 10, 300 at 200: every T in 11..200 separates them with the
    // same between-class variance; the middle of that run is (11 + 200) / 2 = 105.
    Histogram histogram{};
    histogram[10] = 700;
    histogram[200] = 300;
    EXPECT_EQ(otsu_threshold(histogram), 105);
}

TEST(Otsu, SplitsTwoBroadModesNearTheirValley) {
    // Two triangles of width 41: around 50 (weight 3) and around 170 (weight 1).
    // The valley runs 71..149 (empty): the threshold lies in it, past the
    // lower mode's last bin (70) and at or before the upper's first (150).
    Histogram histogram{};
    for (int d = -20; d <= 20; ++d) {
        histogram[50 + d] = static_cast<std::uint64_t>(3 * (21 - std::abs(d)));
        histogram[170 + d] = static_cast<std::uint64_t>(21 - std::abs(d));
    }
    const auto threshold = otsu_threshold(histogram);
    ASSERT_TRUE(threshold.has_value());
    EXPECT_GT(*threshold, 70);
    EXPECT_LE(*threshold, 150);
    EXPECT_EQ(*threshold, (71 + 150) / 2);
}

TEST(Otsu, MatchesBruteForceOnAnUnevenHistogram) {
    // Overlapping modes: no plateau, the maximiser checked against a direct
    // evaluation of w0 w1 (m0 - m1)^2 for every T.
    Histogram histogram{};
    for (int v = 0; v < 256; ++v) {
        const double a = 1000.0 * std::exp(-0.5 * std::pow((v - 60) / 25.0, 2));
        const double b = 400.0 * std::exp(-0.5 * std::pow((v - 140) / 30.0, 2));
        histogram[v] = static_cast<std::uint64_t>(a + b);
    }
    int best_t = -1;
    double best = -1.0;
    for (int t = 1; t < 256; ++t) {
        double n0 = 0, s0 = 0, n1 = 0, s1 = 0;
        for (int v = 0; v < 256; ++v) {
            const double count = static_cast<double>(histogram[v]);
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
    EXPECT_EQ(otsu_threshold(histogram), best_t);
    EXPECT_GT(best_t, 60);
    EXPECT_LT(best_t, 140);
}

TEST(Otsu, NoSplitWithoutTwoValues) {
    EXPECT_FALSE(otsu_threshold(Histogram{}).has_value());
    Histogram single{};
    single[0] = 5000;  // bare soil, all ExG clipped to 0: Otsu has nothing to split
    EXPECT_FALSE(otsu_threshold(single).has_value());
}

TEST(PerspectiveTransform, MapsTheFourCornersAndStraightLines) {
    const std::array<Eigen::Vector2d, 4> rectangle{Eigen::Vector2d(0, 200), Eigen::Vector2d(300, 200), Eigen::Vector2d(300, 0),
                                                   Eigen::Vector2d(0, 0)};
    const std::array<Eigen::Vector2d, 4> trapezoid{Eigen::Vector2d(399, 573), Eigen::Vector2d(761, 573), Eigen::Vector2d(748, 355),
                                                   Eigen::Vector2d(423, 355)};
    const Eigen::Matrix3d m = perspective_transform(rectangle, trapezoid);
    auto apply = [&](Eigen::Vector2d p) {
        const Eigen::Vector3d h = m * Eigen::Vector3d(p.x(), p.y(), 1.0);
        return Eigen::Vector2d(h.x() / h.z(), h.y() / h.z());
    };
    for (int i = 0; i < 4; ++i) EXPECT_NEAR((apply(rectangle[i]) - trapezoid[i]).norm(), 0.0, 1e-9);
    // The rectangle's centre goes to the crossing of the trapezoid's diagonals
    // (a projective map keeps lines and incidence).
    const Eigen::Vector2d centre = apply(Eigen::Vector2d(150, 100));
    const Eigen::Vector2d d1 = trapezoid[2] - trapezoid[0];
    const Eigen::Vector2d d2 = trapezoid[3] - trapezoid[1];
    const Eigen::Vector2d c0 = centre - trapezoid[0];
    const Eigen::Vector2d c1 = centre - trapezoid[1];
    EXPECT_NEAR(d1.x() * c0.y() - d1.y() * c0.x(), 0.0, 1e-6);
    EXPECT_NEAR(d2.x() * c1.y() - d2.y() * c1.x(), 0.0, 1e-6);
    const std::array<Eigen::Vector2d, 4> collinear{Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 1), Eigen::Vector2d(2, 2), Eigen::Vector2d(3, 3)};
    EXPECT_THROW(perspective_transform(collinear, trapezoid), std::invalid_argument);
}

TEST(SampleBilinear, InterpolatesBetweenPixelCentres) {
    rig::camera::RgbImage image(2, 2);
    image.set(0, 0, Rgb{0, 0, 0});
    image.set(1, 0, Rgb{100, 0, 0});
    image.set(0, 1, Rgb{0, 200, 0});
    image.set(1, 1, Rgb{100, 200, 40});
    const auto centre = sample_bilinear(image, 1.0, 1.0);  // midway between the four centres
    ASSERT_TRUE(centre.has_value());
    EXPECT_DOUBLE_EQ((*centre)[0], 50.0);
    EXPECT_DOUBLE_EQ((*centre)[1], 100.0);
    EXPECT_DOUBLE_EQ((*centre)[2], 10.0);
    const auto corner = sample_bilinear(image, 1.5, 0.5);  // pixel (1, 0)'s centre
    ASSERT_TRUE(corner.has_value());
    EXPECT_DOUBLE_EQ((*corner)[0], 100.0);
    EXPECT_FALSE(sample_bilinear(image, 0.2, 1.0).has_value());
    EXPECT_FALSE(sample_bilinear(image, 1.0, 1.7).has_value());
}

}  // namespace
