// The trace digest's input, as the writer thread now feeds it: the canonical
// lines (harness/trace/trace_file.h) added piece by piece into a Sha256 that
// gathers small pieces into a buffer before hashing them. The digest must be
// the one of the lines as whole strings, hashed at once: these compare the
// two on lines written out by hand, on numbers in nlohmann's format, and on
// input split at every size around the buffer's, with SHA-256 known answers
// beneath them.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/trace/sha256.h"
#include "harness/trace/trace_file.h"

namespace {

using rig::harness::Sha256;

// SHA-256 of `text` handed over in one piece: a single EVP update of all of
// it, whatever its size (below the buffer's, it is hashed from the buffer
// whole; from it up, directly), the reference the pieces must give.
std::string one_shot_sha256(const std::string& text) {
    Sha256 digest;
    digest.add(text);
    return digest.hex();
}

// Bytes that differ at every position, so a piece dropped, doubled or moved shows.
std::string counting_bytes(std::size_t size) {
    std::string bytes(size, '\0');
    for (std::size_t i = 0; i < size; ++i) bytes[i] = static_cast<char>((i * 131 + i / 251) & 0xff);
    return bytes;
}

TEST(Sha256, PiecesOfAnySizeGiveTheDigestOfTheWholeInput) {
    const std::string input = counting_bytes(100'000);
    const std::string expected = one_shot_sha256(input);
    // Pieces of one size each time: single bytes, line-sized, and around the
    // 16 KiB buffer (just under, at, just over, several times over).
    for (const std::size_t piece : {std::size_t{1}, std::size_t{7}, std::size_t{130}, std::size_t{16383},
                                    std::size_t{16384}, std::size_t{16385}, std::size_t{40000}, input.size()}) {
        Sha256 digest;
        for (std::size_t at = 0; at < input.size(); at += piece) {
            digest.add(input.data() + at, std::min(piece, input.size() - at));
        }
        EXPECT_EQ(digest.hex(), expected) << "pieces of " << piece << " bytes";
    }
    // Pieces of changing sizes, a large one after a partly filled buffer.
    Sha256 mixed;
    std::size_t at = 0;
    for (const std::size_t piece : {std::size_t{5}, std::size_t{16380}, std::size_t{20000}, std::size_t{1},
                                    std::size_t{0}, std::size_t{33000}}) {
        mixed.add(input.data() + at, piece);
        at += piece;
    }
    mixed.add(input.data() + at, input.size() - at);
    EXPECT_EQ(mixed.hex(), expected);
}

TEST(Sha256, KnownAnswers) {
    // FIPS 180-2's examples: the reference above is SHA-256 itself.
    EXPECT_EQ(one_shot_sha256(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
    EXPECT_EQ(one_shot_sha256("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
    Sha256 in_pieces;
    for (const char c : std::string("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq")) in_pieces.add(c);
    EXPECT_EQ(in_pieces.hex(), "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
}

TEST(TraceDigest, EachRowAddsItsCanonicalLine) {
    // The lines written out as the trace format defines them (docs/trace-format.md).
    const std::string sample_json = R"({"along_m":1.5,"pass_index":0})";
    const std::vector<unsigned char> cdr = {0, 1, 0, 0, 42, 0, 0, 0};
    std::string lines;
    lines += "-5 0 truth/vehicle " + sample_json + "\n";
    lines += "9223372036854775807 63 device/gnss/nmea \"$GPGGA\"\n";
    lines += "deposition 1 18446744073709551615 23 0.1\n";
    lines += "deposition 0 0 0 1e-05\n";
    lines += "deposition 0 7 3 0.0\n";
    lines += "deposition 0 8 3 null\n";
    lines += "deposition 0 9 3 " + nlohmann::json(2.0 / 3.0).dump() + "\n";
    lines += "landing 1500000000 1\n";
    lines += "landing 0 0\n";

    Sha256 digest;
    rig::harness::add_sample_digest(digest, -5, 0, "truth/vehicle", sample_json);
    rig::harness::add_sample_digest(digest, std::numeric_limits<std::int64_t>::max(), 63, "device/gnss/nmea",
                                    "\"$GPGGA\"");
    rig::harness::add_deposition_digest(digest, 1, std::numeric_limits<std::size_t>::max(), 23, 0.1);
    rig::harness::add_deposition_digest(digest, 0, 0, 0, 1e-05);
    rig::harness::add_deposition_digest(digest, 0, 7, 3, 0.0);
    rig::harness::add_deposition_digest(digest, 0, 8, 3, std::nan(""));
    rig::harness::add_deposition_digest(digest, 0, 9, 3, 2.0 / 3.0);
    rig::harness::add_landing_digest(digest, 1'500'000'000, true);
    rig::harness::add_landing_digest(digest, 0, false);
    EXPECT_EQ(digest.hex(), one_shot_sha256(lines));

    // The bytes' digest: "t_ns round topic size\n", then the bytes.
    Sha256 cdr_digest;
    rig::harness::add_cdr_digest(cdr_digest, 250, 2, "device/wheel_encoder/count", cdr.data(), cdr.size());
    EXPECT_EQ(cdr_digest.hex(), one_shot_sha256("250 2 device/wheel_encoder/count 8\n" +
                                                std::string(cdr.begin(), cdr.end())));
}

}  // namespace
