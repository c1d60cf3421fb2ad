// The main() of every GoogleTest binary (rig_add_test, cmake/RigHelpers.cmake),
// in place of GoogleTest's own. ctest sees one exit status per binary, and
// GoogleTest's exits 0 both when every selected test passed and when none of
// them checked anything. Two of those are told apart here:
//  * every test that ran was skipped (GTEST_SKIP): exit kAllSkipped, which
//    ctest's SKIP_RETURN_CODE shows as "Not Run" instead of "Passed". A binary
//    with some tests skipped and the rest passing still passes; scripts/test
//    names its skipped tests from the XML reports.
//  * no test was selected at all (a --gtest_filter that matches nothing, such
//    as a *RealTime* filter after a rename): a failure, not a pass.
#include <gtest/gtest.h>

#include <cstdio>

namespace {

// The exit status for "all skipped" (automake's convention for a skipped
// test); tests/CMakeLists.txt's SKIP_RETURN_CODE says the same number.
constexpr int kAllSkipped = 77;

class RunCounter : public ::testing::EmptyTestEventListener {
public:
    // --gtest_list_tests and --help return before any iteration: nothing was meant to run.
    void OnTestIterationStart(const ::testing::UnitTest&, int) override { iterated_ = true; }
    void OnTestEnd(const ::testing::TestInfo& test) override {
        ++ran_;
        if (test.result()->Skipped()) ++skipped_;
    }
    bool iterated() const { return iterated_; }
    int ran() const { return ran_; }
    int skipped() const { return skipped_; }

private:
    bool iterated_ = false;
    int ran_ = 0;
    int skipped_ = 0;
};

}  // namespace

int main(int argc, char** argv) {
    ::testing::InitGoogleTest(&argc, argv);
    // Owned by GoogleTest's listener list once appended; kept alive until exit.
    auto* counter = new RunCounter;
    ::testing::UnitTest::GetInstance()->listeners().Append(counter);
    const int status = RUN_ALL_TESTS();
    if (status != 0 || !counter->iterated()) return status;
    if (counter->ran() == 0) {
        std::fprintf(stderr, "no test matched the filter: nothing was checked\n");
        return 1;
    }
    if (counter->skipped() == counter->ran()) {
        std::fprintf(stderr, "every selected test was skipped (%d): nothing was checked (exit status %d: skipped)\n",
                     counter->ran(), kAllSkipped);
        return kAllSkipped;
    }
    return 0;
}
