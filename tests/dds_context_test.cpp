// rig::DdsContext with a node that outlives it: a controller whose main()
// declares its node before its context destroys the context first. The
// node's readers and writers must then neither touch the freed context nor
// leak DDS entities (the SDK example and the boundary controller once did the
// former; ASan saw it). Runs under ASan in CI like every test.
#include <gtest/gtest.h>

#include <memory>

#include "idl/topics.h"
#include "rig/host/domain_lease.h"
#include "rig/runtime/dds_context.h"

namespace {

TEST(DdsContext, EndpointsOutlivingTheirContextAreDetachedNotDangling) {
    const rig::DomainLease lease = rig::DomainLease::acquire();
    auto dds = std::make_unique<rig::DdsContext>(lease.domain_id(), "outlived");
    auto writer = std::make_unique<rig::Writer<rig::msg::NmeaSentence>>(*dds, rig::topics::kDdsCheckPing);
    auto reader = std::make_unique<rig::Reader<rig::msg::NmeaSentence>>(*dds, rig::topics::kDdsCheckPing);
    EXPECT_EQ(dds->writers().size(), 1u);
    EXPECT_EQ(dds->readers().size(), 1u);

    dds.reset();  // the context goes first

    rig::msg::NmeaSentence sample;
    sample.sentence("$GPGGA");
    // Writing through a detached writer is an error the caller sees, not a crash.
    EXPECT_THROW(writer->publish(sample), std::runtime_error);
    EXPECT_FALSE(writer->wait_delivered(std::chrono::milliseconds(1)));
    EXPECT_FALSE(reader->has_unread());
    EXPECT_TRUE(reader->take_all().empty());
    EXPECT_FALSE(reader->wait_for_data(std::chrono::milliseconds(1)));
    writer.reset();
    reader.reset();
}

TEST(DdsContext, EndpointsDestroyedFirstLeaveTheRegistry) {
    const rig::DomainLease lease = rig::DomainLease::acquire();
    rig::DdsContext dds(lease.domain_id(), "ordinary");
    {
        rig::Writer<rig::msg::NmeaSentence> writer(dds, rig::topics::kDdsCheckPing);
        rig::Reader<rig::msg::NmeaSentence> reader(dds, rig::topics::kDdsCheckPing);
        EXPECT_EQ(dds.writers().size(), 1u);
        EXPECT_EQ(dds.readers().size(), 1u);
    }
    EXPECT_TRUE(dds.writers().empty());
    EXPECT_TRUE(dds.readers().empty());
}

}  // namespace
