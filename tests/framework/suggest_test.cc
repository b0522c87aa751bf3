// "Did you mean ...?" (framework/suggest.cc): the rule behind the loader's
// unknown keys and the host's misspelt sysCall_* names.
#include "framework/suggest.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace swarmsim {
namespace {

TEST(SuggestTest, EditDistanceCountsInsertionsDeletionsSubstitutionsAndSwaps) {
  EXPECT_EQ(EditDistance("", ""), 0);
  EXPECT_EQ(EditDistance("", "abc"), 3);
  EXPECT_EQ(EditDistance("radius", "radius"), 0);
  EXPECT_EQ(EditDistance("raduis", "radius"), 1);  // two neighbours swapped: one edit
  EXPECT_EQ(EditDistance("radus", "radius"), 1);
  EXPECT_EQ(EditDistance("radiuss", "radius"), 1);
  EXPECT_EQ(EditDistance("rodius", "radius"), 1);
  EXPECT_EQ(EditDistance("kitten", "sitting"), 3);
  // Symmetric, and a swap is one edit in either direction.
  EXPECT_EQ(EditDistance("sitting", "kitten"), 3);
  EXPECT_EQ(EditDistance("ba", "ab"), 1);
  // Optimal string alignment: a swapped pair is not edited again.
  EXPECT_EQ(EditDistance("ca", "abc"), 3);
}

TEST(SuggestTest, NearestNameIsATypoOfACandidateOrNothing) {
  const std::vector<std::string> keys = {"robots", "radius", "range", "rate"};
  ASSERT_NE(NearestName("robts", keys), nullptr);
  EXPECT_EQ(*NearestName("robts", keys), "robots");
  EXPECT_EQ(*NearestName("raduis", keys), "radius");
  // Nothing near: a different word altogether.
  EXPECT_EQ(NearestName("gravity", keys), nullptr);
  EXPECT_EQ(NearestName("anything", std::vector<std::string>{}), nullptr);
  // Short names: two edits that change every character are not a typo.
  EXPECT_EQ(NearestName("ab", std::vector<std::string>{"xy"}), nullptr);
  EXPECT_EQ(*NearestName("ab", std::vector<std::string>{"ax"}), "ax");
  // Long names allow a third of their length: 3 edits in 9 characters.
  const std::vector<std::string> long_name = {"time_step"};
  EXPECT_EQ(EditDistance("tyme_stap", "time_step"), 2);
  EXPECT_EQ(EditDistance("tyme_stxx", "time_step"), 3);
  EXPECT_NE(NearestName("tyme_stxx", long_name), nullptr);
  EXPECT_EQ(EditDistance("tyxe_stxx", "time_step"), 4);
  EXPECT_EQ(NearestName("tyxe_stxx", long_name), nullptr);
  // Of equally near candidates, the first wins.
  const std::vector<std::string> tied = {"rate", "gate"};
  EXPECT_EQ(*NearestName("xate", tied), "rate");
  const std::vector<std::string> tied_reversed = {"gate", "rate"};
  EXPECT_EQ(*NearestName("xate", tied_reversed), "gate");
  // A name cut short: the shortest candidate that begins with it, though
  // another is fewer edits away.
  const std::vector<std::string> devices = {"with_leds", "with_rab", "with_camera",
                                            "with_camera_blobs"};
  EXPECT_LT(EditDistance("with_cam", "with_rab"), EditDistance("with_cam", "with_camera"));
  EXPECT_EQ(*NearestName("with_cam", devices), "with_camera");
  EXPECT_EQ(*NearestName("with_ra", devices), "with_rab");
  EXPECT_EQ(NearestName("wi", std::vector<std::string>{"with_rab"}), nullptr);  // too short
  // A whole word of the other: a key with a unit or a qualifier added or dropped.
  const std::vector<std::string> sensor = {"range", "noise", "max_speed", "aperture"};
  EXPECT_EQ(*NearestName("noise_std", sensor), "noise");
  EXPECT_EQ(*NearestName("speed", sensor), "max_speed");
  EXPECT_EQ(NearestName("noisy_std", sensor), nullptr);  // words must match whole
  EXPECT_EQ(NearestName("fov", sensor), nullptr);
}

TEST(SuggestTest, SuggestNamesTheNearestOrListsThemAll) {
  const std::vector<std::string> keys = {"physics", "time_step", "seed"};
  EXPECT_EQ(Suggest("phyiscs", keys), "; did you mean 'physics'?");
  EXPECT_EQ(Suggest("colour", keys), " (expected one of: physics, time_step, seed)");
  // Every key of a section, however many.
  std::vector<std::string> keys20;
  for (int i = 0; i < 20; ++i) keys20.push_back("key_number_" + std::to_string(i));
  const std::string all = Suggest("colour", keys20);
  EXPECT_NE(all.find("key_number_0, key_number_1,"), std::string::npos) << all;
  EXPECT_NE(all.find(", key_number_19)"), std::string::npos) << all;
  EXPECT_EQ(all.find("more"), std::string::npos) << all;
  // A long list (every path of a URDF model): what fits in 400 characters and a count.
  std::vector<std::string> many;
  for (int i = 0; i < 100; ++i) many.push_back("/robot/base/link_" + std::to_string(i));
  const std::string cut = Suggest("gripper", many);
  EXPECT_NE(cut.find(" (expected one of: /robot/base/link_0, /robot/base/link_1,"),
            std::string::npos)
      << cut;
  EXPECT_NE(cut.find(", ... (81 more))"), std::string::npos) << cut;
  EXPECT_LT(cut.size(), 460u);
  EXPECT_EQ(Suggest("anything", std::vector<std::string>{}), "");
}

}  // namespace
}  // namespace swarmsim
