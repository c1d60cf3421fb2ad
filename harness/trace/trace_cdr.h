#pragma once
// The trace's binary form of a sample: its CDR bytes, encapsulation header
// first, exactly as DDS carries it (docs/trace-format.md, `samples.cdr`).
//
// The lockstep loop only serializes each sample it records (a copy of a few
// dozen bytes, no text); the trace's rendering thread renders the JSON text from
// those bytes (the digest is taken over that text, as before) and its storing
// thread stores both;
// the judge decodes the bytes straight into JSON values, with no text to parse.
// Rendering text and parsing it back took about 5 % of a case's CPU in process
// (nlohmann's lexer and dtoa), most of it on the loop's thread.
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include <fastcdr/Cdr.h>
#include <fastcdr/FastBuffer.h>
#include <fastcdr/exceptions/Exception.h>
#include <nlohmann/json.hpp>

#include "harness/trace/trace_json.h"
#include "msg_traits.h"

namespace rig::harness {

// How the trace stores and reads one IDL type.
struct SampleCodec {
    std::string type_name;  // the IDL's, as DDS names it: rig::msg::VehicleTruth
    // Appends the sample's CDR bytes (a `const Msg*` of the codec's type) to `out`.
    void (*append_cdr)(const void* sample, std::vector<unsigned char>& out);
    // The sample's JSON text (harness/trace/trace_json.h), byte for byte what
    // the trace stored before it kept the bytes: the digest is over it.
    std::string (*json_text)(const unsigned char* cdr, std::size_t size);
    // The sample as a JSON value: the same value, with the same number kinds,
    // as parsing its JSON text gives.
    nlohmann::json (*json_value)(const unsigned char* cdr, std::size_t size);
};

namespace cdr_detail {

template <class Msg>
void append_cdr(const void* sample, std::vector<unsigned char>& out) {
    const Msg& typed = *static_cast<const Msg*>(sample);
    const std::size_t at = out.size();
    // The encapsulation header, then at most the type's own size for this sample.
    out.resize(at + 4 + Msg::getCdrSerializedSize(typed));
    eprosima::fastcdr::FastBuffer buffer(reinterpret_cast<char*>(out.data() + at), out.size() - at);
    eprosima::fastcdr::Cdr cdr(buffer, eprosima::fastcdr::Cdr::DEFAULT_ENDIAN, eprosima::fastcdr::Cdr::DDS_CDR);
    cdr.serialize_encapsulation();
    typed.serialize(cdr);
    out.resize(at + cdr.getSerializedDataLength());
}

// Throws std::runtime_error naming the type when the bytes are not one of its samples.
template <class Msg>
Msg decoded(const unsigned char* bytes, std::size_t size, const std::string& type_name) {
    Msg sample;
    // FastBuffer wants a mutable buffer; deserializing only reads it.
    eprosima::fastcdr::FastBuffer buffer(reinterpret_cast<char*>(const_cast<unsigned char*>(bytes)), size);
    eprosima::fastcdr::Cdr cdr(buffer, eprosima::fastcdr::Cdr::DEFAULT_ENDIAN, eprosima::fastcdr::Cdr::DDS_CDR);
    try {
        cdr.read_encapsulation();
        sample.deserialize(cdr);
    } catch (const eprosima::fastcdr::exception::Exception& error) {
        throw std::runtime_error(std::to_string(size) + " bytes that are not the CDR of a " + type_name + " (" +
                                 error.what() + ")");
    }
    return sample;
}

template <class Msg>
const std::string& type_name() {
    static const std::string name = typename MsgTraits<Msg>::PubSubType().getName();
    return name;
}

}  // namespace cdr_detail

// The codec of a type the trace records (every type to_json_text knows).
template <class Msg>
const SampleCodec& sample_codec() {
    static const SampleCodec codec{
        cdr_detail::type_name<Msg>(), &cdr_detail::append_cdr<Msg>,
        [](const unsigned char* bytes, std::size_t size) {
            return to_json_text(cdr_detail::decoded<Msg>(bytes, size, cdr_detail::type_name<Msg>()));
        },
        [](const unsigned char* bytes, std::size_t size) {
            return to_json_value(cdr_detail::decoded<Msg>(bytes, size, cdr_detail::type_name<Msg>()));
        }};
    return codec;
}

// The codec of a type by its IDL name (a trace's `sample_types` table), or
// null for a type the trace does not record as bytes.
const SampleCodec* sample_codec_named(std::string_view type_name);

}  // namespace rig::harness
