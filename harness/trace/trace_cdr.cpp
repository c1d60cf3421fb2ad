#include "harness/trace/trace_cdr.h"

#include <array>

namespace rig::harness {

const SampleCodec* sample_codec_named(std::string_view type_name) {
#define RIG_CODEC_OF(Type) &sample_codec<msg::Type>(),
    static const std::array codecs = {RIG_TRACE_RECORDED_TYPES(RIG_CODEC_OF)};
#undef RIG_CODEC_OF
    for (const SampleCodec* codec : codecs) {
        if (codec->type_name == type_name) return codec;
    }
    return nullptr;
}

}  // namespace rig::harness
