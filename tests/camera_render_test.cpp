// The camera emulator's renderer (emulators/vision/camera_emulator.*) against
// the crop truth it draws: a pixel that sees one kind of ground only has that
// ground's colour, a leaf edge gives mixed pixels on the soil-plant line when
// a pixel's footprint is sampled n x n (one sample: soil or plant), the
// noise is seeded (same frame, same bytes; another seed, other noise) and of
// the configured size, and where the renderer happens to keep its block of the
// truth never shows in a frame.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "emulators/field2d/crop_cover_map.h"
#include "emulators/vision/camera_emulator.h"

namespace {

using rig::camera::Rgb;
using rig::camera::RgbImage;
using rig::emulators::vision::BoomPose;
using rig::emulators::vision::CameraEmulator;
using rig::emulators::vision::CameraEmulatorParams;
using rig::emulators::vision::seed001_camera_params;
using rig::field2d::CoverClass;
using rig::field2d::CropCoverMap;
using rig::field2d::CropCoverParams;
using rig::field2d::Vec2;

CameraEmulatorParams noiseless(int samples_per_axis) {
    CameraEmulatorParams params = seed001_camera_params(false);
    params.noise_sd_dn = 0.0;
    params.samples_per_axis = samples_per_axis;
    return params;
}

bool same(Rgb a, Rgb b) { return a.r == b.r && a.g == b.g && a.b == b.b; }

// True when every truth cell within `reach_m` of `ground` is plant (or, for
// false, soil): a pixel centred there sees that ground only.
std::optional<bool> uniform_around(const CropCoverMap& crop, Vec2 ground, double reach_m) {
    const bool centre = crop.is_plant(ground);
    for (double de = -reach_m; de <= reach_m; de += 0.0005) {
        for (double dn = -reach_m; dn <= reach_m; dn += 0.0005) {
            if (crop.is_plant(ground + Vec2{de, dn}) != centre) return std::nullopt;
        }
    }
    return centre;
}

// Pixels in the lower half of the frame (footprints under 3 mm) that see one
// kind of ground within 6 mm have exactly that ground's colour; both kinds occur.
void expect_matches_truth(int samples_per_axis) {
    const CropCoverMap crop(CropCoverParams{}, 3);
    const CameraEmulator camera(noiseless(samples_per_axis), 3, 0, "left");
    const BoomPose pose{{1.0, 2.0}, 20.0, 0.5};
    const auto image = camera.render(crop, pose, 0);
    ASSERT_TRUE(image.has_value());
    const Rgb soil = camera.params().soil_rgb;
    const Rgb plant = camera.params().plant_rgb;
    int plant_pixels = 0;
    int soil_pixels = 0;
    for (int v = 380; v < 720; v += 9) {
        for (int u = 3; u < 1280; u += 17) {
            const auto ground = camera.ground_seen(pose, u + 0.5, v + 0.5);
            ASSERT_TRUE(ground.has_value());
            const std::optional<bool> plant_here = uniform_around(crop, *ground, 0.006);
            if (!plant_here) continue;
            const Rgb seen = image->at(u, v);
            EXPECT_TRUE(same(seen, *plant_here ? plant : soil))
                << "pixel (" << u << ", " << v << ") is " << int(seen.r) << "/" << int(seen.g) << "/" << int(seen.b) << " over "
                << (*plant_here ? "plant" : "soil");
            (*plant_here ? plant_pixels : soil_pixels) += 1;
        }
    }
    EXPECT_GT(plant_pixels, 50);
    EXPECT_GT(soil_pixels, 50);
}

TEST(CameraRender, OneSampleMatchesCropTruth) { expect_matches_truth(1); }
TEST(CameraRender, FootprintSamplesMatchCropTruth) { expect_matches_truth(2); }

TEST(CameraRender, OneSampleGivesNoMixedPixels) {
    const CropCoverMap crop(CropCoverParams{}, 4);
    const CameraEmulator camera(noiseless(1), 4, 0, "left");
    const auto image = camera.render(crop, BoomPose{{0.0, 0.0}, 0.0, 0.5}, 0);
    for (int v = 0; v < image->height; ++v) {
        for (int u = 0; u < image->width; ++u) {
            const Rgb seen = image->at(u, v);
            ASSERT_TRUE(same(seen, camera.params().soil_rgb) || same(seen, camera.params().plant_rgb)) << u << ", " << v;
        }
    }
}

TEST(CameraRender, FootprintSamplesGiveMixedPixelsOnTheSoilPlantLine) {
    const CropCoverMap crop(CropCoverParams{}, 4);
    const CameraEmulator camera(noiseless(2), 4, 0, "left");
    const auto image = camera.render(crop, BoomPose{{0.0, 0.0}, 0.0, 0.5}, 0);
    ASSERT_TRUE(image.has_value());
    const Rgb soil = camera.params().soil_rgb;
    const Rgb plant = camera.params().plant_rgb;
    int mixed = 0;
    for (int v = 0; v < image->height; ++v) {
        for (int u = 0; u < image->width; ++u) {
            const Rgb seen = image->at(u, v);
            if (same(seen, soil) || same(seen, plant)) continue;
            ++mixed;
            // A mix: the plant share from green, the others follow within rounding.
            const double share = (seen.g - soil.g) / double(plant.g - soil.g);
            ASSERT_GE(share, 0.0);
            ASSERT_LE(share, 1.0);
            // Each channel rounds on its own: green's half DN spreads to the others.
            const double slack = 0.5 * std::abs(plant.r - soil.r) / std::abs(plant.g - soil.g) + 1.0;
            EXPECT_NEAR(seen.r, soil.r + share * (plant.r - soil.r), slack);
            EXPECT_NEAR(seen.b, soil.b + share * (plant.b - soil.b), slack);
        }
    }
    // Leaves 8 mm wide under pixels of 1.7-3.6 mm: a good share of the plant pixels are edges.
    // (With 2 x 2 samples a mix is a quarter, a half or three quarters.)
    EXPECT_GT(mixed, 10'000);
}

TEST(CameraRender, SameFrameSameBytesOtherFrameOrSeedOtherNoise) {
    const CropCoverMap crop(CropCoverParams{}, 5);
    CameraEmulatorParams params = seed001_camera_params(false);
    params.samples_per_axis = 1;
    const CameraEmulator camera(params, 5, 0, "left");
    const CameraEmulator twin(params, 5, 0, "left");
    const CameraEmulator other_seed(params, 6, 0, "left");
    const CameraEmulator other_stream(params, 5, 1, "left");
    const BoomPose pose{{0.0, 1.0}, 0.0, 0.5};
    const auto first = camera.render(crop, pose, 7);
    EXPECT_EQ(camera.render(crop, pose, 7)->bytes, first->bytes);
    EXPECT_EQ(twin.render(crop, pose, 7)->bytes, first->bytes);
    EXPECT_NE(camera.render(crop, pose, 8)->bytes, first->bytes);
    EXPECT_NE(other_seed.render(crop, pose, 7)->bytes, first->bytes);
    EXPECT_NE(other_stream.render(crop, pose, 7)->bytes, first->bytes);
}

TEST(CameraRender, FrameDoesNotDependOnWhatWasRenderedBefore) {
    // The renderer keeps a block of the truth between frames; a frame after a
    // drive (the block moved, or kept) equals the same frame from a fresh camera.
    const CropCoverMap crop(CropCoverParams{}, 6);
    const CropCoverMap other_crop(CropCoverParams{}, 6);
    CameraEmulatorParams params = seed001_camera_params(true);
    const CameraEmulator driven(params, 6, 1, "right");
    for (int step = 0; step < 12; ++step) driven.render(crop, BoomPose{{0.0, 0.13 * step}, 0.0, 0.5}, 0);
    const BoomPose pose{{0.0, 0.13 * 11 + 0.05}, 0.0, 0.5};
    const auto after_drive = driven.render(crop, pose, 3);
    const auto fresh = CameraEmulator(params, 6, 1, "right").render(other_crop, pose, 3);
    EXPECT_EQ(after_drive->bytes, fresh->bytes);
}

TEST(CameraRender, NoiseOnFlatSoilHasTheConfiguredSpread) {
    CropCoverParams bare;
    bare.default_cover = CoverClass::bare;
    const CropCoverMap crop(bare, 7);
    for (const double noise_sd : {3.0, 6.0, 12.0}) {
        CameraEmulatorParams params = seed001_camera_params(false);
        params.noise_sd_dn = noise_sd;
        params.samples_per_axis = 1;
        const CameraEmulator camera(params, 7, 0, "left");
        const auto image = camera.render(crop, BoomPose{}, 11);
        const Rgb soil = params.soil_rgb;
        for (int channel = 0; channel < 3; ++channel) {
            const double truth = channel == 0 ? soil.r : channel == 1 ? soil.g : soil.b;
            double sum = 0.0;
            double sum_sq = 0.0;
            const std::size_t pixel_count = image->bytes.size() / 3;
            const auto pixels = static_cast<double>(pixel_count);
            for (std::size_t i = 0; i < pixel_count; ++i) {
                const double error = image->bytes[3 * i + static_cast<std::size_t>(channel)] - truth;
                sum += error;
                sum_sq += error * error;
            }
            const double mean = sum / pixels;
            const double sd = std::sqrt(sum_sq / pixels - mean * mean);
            EXPECT_NEAR(mean, 0.0, 0.05) << "noise " << noise_sd << " channel " << channel;
            // Rounding to whole DN adds 1/12 DN^2 of variance.
            EXPECT_NEAR(sd, std::sqrt(noise_sd * noise_sd + 1.0 / 12.0), 0.03 * noise_sd) << "noise " << noise_sd << " channel " << channel;
        }
    }
}

TEST(CameraRender, ViewOverTheHorizonShowsSkyAndGround) {
    // Pitched 80 deg forward: the top rows see over the horizon (sky), the
    // bottom rows the ground; a view that long takes the exact path.
    CameraEmulatorParams params = noiseless(1);
    params.camera.mounting.pitch_deg = 80.0;
    const CropCoverMap crop(CropCoverParams{}, 8);
    const CameraEmulator camera(params, 8, 0, "left");
    const BoomPose pose{{0.0, 0.0}, 0.0, 0.5};
    const auto image = camera.render(crop, pose, 0);
    EXPECT_TRUE(same(image->at(640, 0), params.sky_rgb));
    const auto ground = camera.ground_seen(pose, 640.5, 719.5);
    ASSERT_TRUE(ground.has_value());
    const std::optional<bool> plant_here = uniform_around(crop, *ground, 0.02);
    if (plant_here) {
        EXPECT_TRUE(same(image->at(640, 719), *plant_here ? params.plant_rgb : params.soil_rgb));
    }
}

TEST(CameraRender, FarFromTheOriginIsAClearError) {
    const CropCoverMap crop(CropCoverParams{}, 9);
    const CameraEmulator camera(noiseless(1), 9, 0, "left");
    try {
        camera.render(crop, BoomPose{{2e6, 0.0}, 0.0, 0.5}, 0);
        FAIL() << "a boom 2000 km out rendered";
    } catch (const std::invalid_argument& error) {
        EXPECT_NE(std::string(error.what()).find("left: boom centre"), std::string::npos) << error.what();
    }
    EXPECT_THROW(camera.render(crop, BoomPose{{0.0, 0.0}, 0.0, 0.0}, 0), std::invalid_argument);
}

TEST(CropCoverCells, CopyAgreesWithIsPlant) {
    const CropCoverMap crop(CropCoverParams{}, 10);
    const int cols = 700;
    const int rows = 300;
    std::vector<std::uint8_t> cells(static_cast<std::size_t>(cols) * rows);
    crop.copy_cells(-350, -20, cols, rows, cells.data(), cols);
    int plant = 0;
    for (int j = 0; j < rows; ++j) {
        for (int i = 0; i < cols; ++i) {
            const bool truth = crop.is_plant(Vec2{(-350 + i + 0.5) * 0.001, (-20 + j + 0.5) * 0.001});
            ASSERT_EQ(cells[static_cast<std::size_t>(j) * cols + i], truth ? CropCoverMap::kPlantCell : 0) << i << ", " << j;
            plant += truth;
        }
    }
    EXPECT_GT(plant, 1000);
    EXPECT_THROW(crop.copy_cells(0, 0, 0, 5, cells.data(), 1), std::invalid_argument);
    EXPECT_THROW(crop.copy_cells(999'999'999, 0, 5, 5, cells.data(), 5), std::invalid_argument);
}

TEST(CropCoverCells, BitsAreTheBytesOneBitACell) {
    // A block across tile edges on both sides of the origin (tiles are 256
    // cells), read both ways: bit k of word w is the byte of cell 64 w + k.
    const CropCoverMap crop(CropCoverParams{}, 12);
    const std::int64_t east = -640;
    const std::int64_t north = -300;
    const int words = 14;  // 896 cells
    const int cols = words * CropCoverMap::kCellsPerWord;
    const int rows = 610;
    std::vector<std::uint8_t> cells(static_cast<std::size_t>(cols) * rows);
    crop.copy_cells(east, north, cols, rows, cells.data(), cols);
    const std::size_t stride = words + 3;  // rows further apart than they are long
    std::vector<std::uint64_t> bits(stride * rows, 0x5a5a5a5a5a5a5a5aULL);
    crop.copy_cell_bits(east, north, words, rows, bits.data(), stride);
    int plant = 0;
    for (int j = 0; j < rows; ++j) {
        for (int i = 0; i < cols; ++i) {
            const bool bit = ((bits[static_cast<std::size_t>(j) * stride + static_cast<std::size_t>(i / 64)] >> (i % 64)) & 1U) != 0;
            ASSERT_EQ(bit, cells[static_cast<std::size_t>(j) * cols + i] == CropCoverMap::kPlantCell) << i << ", " << j;
            plant += bit ? 1 : 0;
        }
        for (std::size_t w = words; w < stride; ++w) ASSERT_EQ(bits[static_cast<std::size_t>(j) * stride + w], 0x5a5a5a5a5a5a5a5aULL);
    }
    EXPECT_GT(plant, 50000);
    EXPECT_LT(plant, cols * rows - 50000);
    try {
        crop.copy_cell_bits(-630, 0, 1, 1, bits.data(), 1);
        FAIL() << "a block off the words' grid was copied";
    } catch (const std::invalid_argument& error) {
        EXPECT_NE(std::string(error.what()).find("crop copy_cell_bits"), std::string::npos) << error.what();
        EXPECT_NE(std::string(error.what()).find("(-630, 0)"), std::string::npos) << error.what();
    }
    EXPECT_THROW(crop.copy_cell_bits(0, 0, 0, 5, bits.data(), 1), std::invalid_argument);
    EXPECT_THROW(crop.copy_cell_bits(999'999'936, 0, 2, 5, bits.data(), 2), std::invalid_argument);
}

}  // namespace
