#pragma once
// SHA-256 as hex text (OpenSSL's EVP), as the trace digests are written: the
// judge's recomputed trace digest and the digest of each camera frame.
#include <openssl/evp.h>

#include <cstddef>
#include <string>

namespace rig::harness {

class Sha256 {
public:
    Sha256() : context_(EVP_MD_CTX_new()) { EVP_DigestInit_ex(context_, EVP_sha256(), nullptr); }
    ~Sha256() { EVP_MD_CTX_free(context_); }
    Sha256(const Sha256&) = delete;
    Sha256& operator=(const Sha256&) = delete;
    void add(const void* data, std::size_t size) { EVP_DigestUpdate(context_, data, size); }
    void add(const std::string& text) { add(text.data(), text.size()); }
    // The digest of everything added, as 64 lower-case hex digits (once).
    std::string hex() {
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
    EVP_MD_CTX* context_;
};

}  // namespace rig::harness
