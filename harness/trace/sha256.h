#pragma once
// SHA-256 as hex text (OpenSSL's EVP), as the trace digests are written: the
// judge's recomputed trace digest and the digest of each camera frame.
#include <openssl/evp.h>

#include <array>
#include <cstddef>
#include <cstring>
#include <string>
#include <string_view>

namespace rig::harness {

class Sha256 {
public:
    Sha256() : context_(EVP_MD_CTX_new()) { EVP_DigestInit_ex(context_, EVP_sha256(), nullptr); }
    ~Sha256() { EVP_MD_CTX_free(context_); }
    Sha256(const Sha256&) = delete;
    Sha256& operator=(const Sha256&) = delete;
    // Small pieces are gathered and hashed a buffer at a time: the trace's
    // digest is fed a line of about 130 bytes per sample (trace_file.h), and
    // an EVP call per line cost the trace's writer thread about as much as
    // the hashing itself (docs/speed.md). The digest is of the bytes in
    // order, however they were split.
    void add(const void* data, std::size_t size) {
        if (size > buffer_.size() - used_) {
            flush();
            if (size >= buffer_.size()) {
                EVP_DigestUpdate(context_, data, size);
                return;
            }
        }
        std::memcpy(buffer_.data() + used_, data, size);
        used_ += size;
    }
    void add(std::string_view text) { add(text.data(), text.size()); }
    void add(char c) { add(&c, 1); }
    // The digest of everything added, as 64 lower-case hex digits (once).
    std::string hex() {
        flush();
        unsigned char hash[EVP_MAX_MD_SIZE];
        unsigned int length = 0;
        EVP_DigestFinal_ex(context_, hash, &length);
        static const char* digits = "0123456789abcdef";
        std::string text;
        for (unsigned int i = 0; i < length; ++i) {
            text += digits[hash[i] >> 4];
            text += digits[hash[i] & 0xf];
        }
        return text;
    }

private:
    void flush() {
        if (used_ > 0) EVP_DigestUpdate(context_, buffer_.data(), used_);
        used_ = 0;
    }

    EVP_MD_CTX* context_;
    std::array<unsigned char, 16384> buffer_;
    std::size_t used_ = 0;
};

}  // namespace rig::harness
