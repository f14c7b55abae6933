#include <catch2/catch.hpp>

#include <mutex>
#include <string>
#include <vector>

#include "core/progress.h"

using namespace sprig;

namespace {

/// Records every update it is told of.
struct Recorder final : ProgressObserver {
  std::mutex mutex;
  std::vector<std::string> labels;
  std::vector<uint64_t> done, total;
  void update(const std::string& label, uint64_t d, uint64_t t) override {
    std::lock_guard<std::mutex> lock(mutex);
    labels.push_back(label);
    done.push_back(d);
    total.push_back(t);
  }
};

}  // namespace

TEST_CASE("ProgressSettings::setObserver", "[core]") {
  Recorder r;
  ProgressSettings::setObserver(&r);
  SECTION("a bar reports its first advance and its end; reports between are throttled") {
    {
      Progress bar("tiles", 40);
      for (int i = 0; i < 40; ++i) bar.advance();
      bar.finish();
    }
    ProgressSettings::setObserver(nullptr);
    REQUIRE(r.labels.size() >= 2);
    REQUIRE(r.labels.size() <= 3);  // 40 quick advances fall within one 100 ms interval
    CHECK(r.labels.front() == "tiles");
    CHECK(r.done.front() == 1);
    CHECK(r.done.back() == 40);
    CHECK(r.total.back() == 40);
  }
  SECTION("a bar made while no observer is set reports nothing") {
    ProgressSettings::setObserver(nullptr);
    Progress bar("quiet", 3);
    bar.advance(3);
    bar.finish();
    CHECK(r.labels.empty());
  }
  SECTION("a cancellation request stops a bar; clearCancel withdraws it") {
    Progress bar("cancel", 10);
    ProgressSettings::requestCancel();
    CHECK_THROWS_AS(bar.advance(), Cancelled);
    ProgressSettings::clearCancel();
    CHECK_FALSE(ProgressSettings::cancelRequested());
    CHECK_NOTHROW(bar.advance());
    ProgressSettings::setObserver(nullptr);
  }
  ProgressSettings::setObserver(nullptr);
}
