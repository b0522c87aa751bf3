#include "framework/shared_settings.h"

#include <gtest/gtest.h>

#include <string>
#include <thread>
#include <vector>

namespace swarmsim {
namespace {

struct Settings {
  double range = 0.1;
  std::string name = "default";
};

TEST(SharedSettingsTest, DefaultRowsReadTheDefaultsWithoutOwningAny) {
  const Shared<Settings> a, b;
  EXPECT_DOUBLE_EQ(a->range, 0.1);
  EXPECT_EQ(b->name, "default");
  EXPECT_TRUE(a.SameAs(b));
}

TEST(SharedSettingsTest, CopiesShareUntilOneIsEdited) {
  Shared<Settings> model(Settings{0.5, "ring"});
  std::vector<Shared<Settings>> copies(100, model);
  for (const Shared<Settings>& c : copies) EXPECT_TRUE(c.SameAs(model));

  copies[7].Edit().range = 2;  // one robot's sensor changed
  EXPECT_DOUBLE_EQ(copies[7]->range, 2);
  EXPECT_EQ(copies[7]->name, "ring");  // the rest of its settings came along
  EXPECT_FALSE(copies[7].SameAs(model));
  EXPECT_DOUBLE_EQ(model->range, 0.5);  // the others keep theirs
  EXPECT_DOUBLE_EQ(copies[6]->range, 0.5);
  EXPECT_TRUE(copies[6].SameAs(model));

  // Its own settings now: a second edit does not copy again.
  const Settings* own = &*copies[7];
  copies[7].Edit().name = "mine";
  EXPECT_EQ(&*copies[7], own);
}

TEST(SharedSettingsTest, EditingTheLastHolderChangesInPlace) {
  Shared<Settings> only(Settings{1, "x"});
  const Settings* before = &*only;
  only.Edit().range = 3;
  EXPECT_EQ(&*only, before);
  EXPECT_DOUBLE_EQ(only->range, 3);
}

TEST(SharedSettingsTest, EditingADefaultRowGivesItItsOwn) {
  Shared<Settings> a, b;
  a.Edit().range = 4;
  EXPECT_DOUBLE_EQ(a->range, 4);
  EXPECT_DOUBLE_EQ(b->range, 0.1);  // the defaults are untouched
  EXPECT_DOUBLE_EQ(Shared<Settings>()->range, 0.1);
}

TEST(SharedSettingsTest, AssignmentAndMoveKeepTheCountRight) {
  Shared<Settings> model(Settings{0.3, "m"});
  Shared<Settings> a = model;
  Shared<Settings> b = std::move(a);  // a is left empty: the defaults
  EXPECT_TRUE(b.SameAs(model));
  EXPECT_DOUBLE_EQ(a->range, 0.1);  // NOLINT(bugprone-use-after-move): documented
  b = b;                            // self-assignment keeps it
  EXPECT_TRUE(b.SameAs(model));
  {
    Shared<Settings> c = model;
    c = Shared<Settings>(Settings{9, "other"});
    EXPECT_DOUBLE_EQ(c->range, 9);
  }
  // model and b are the two holders left: editing b copies, model stays.
  b.Edit().range = 1;
  EXPECT_DOUBLE_EQ(model->range, 0.3);
  model.Edit().range = 0.7;  // the last holder: in place
  EXPECT_DOUBLE_EQ(model->range, 0.7);
  EXPECT_DOUBLE_EQ(b->range, 1);
}

// Robots edit their own rows from worker threads at once (a script changing
// its sensor): each ends with its own value and the model keeps its own
// (run under the sanitizer preset, a data race or a double free shows).
TEST(SharedSettingsTest, ConcurrentEditsOfDifferentRowsAreSafe) {
  Shared<Settings> model(Settings{0.5, "ring"});
  std::vector<Shared<Settings>> rows(64, model);
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&rows, t] {
      for (size_t r = t; r < rows.size(); r += 4) rows[r].Edit().range = static_cast<double>(r);
    });
  for (std::thread& t : threads) t.join();
  for (size_t r = 0; r < rows.size(); ++r) EXPECT_DOUBLE_EQ(rows[r]->range, static_cast<double>(r));
  EXPECT_DOUBLE_EQ(model->range, 0.5);
}

// A bulk copy on several threads (Scene::DuplicateSubtrees) counts its
// references in CountCopiesLocally scopes: once the scopes close, the
// counts are whole again. If they were short, editing one copy would change
// the settings every copy shares (it would seem the last holder), and
// dropping the copies would free the settings under the model (a double
// free under the sanitizer preset).
TEST(SharedSettingsTest, CopiesCountedLocallyAreCountedOnceTheScopeCloses) {
  // More distinct settings than a scope keeps counts of (8): the rest are
  // counted at once.
  std::vector<Shared<Settings>> models;
  for (int m = 0; m < 12; ++m)
    models.emplace_back(Settings{static_cast<double>(m), "model " + std::to_string(m)});
  std::vector<std::vector<Shared<Settings>>> copies(models.size(),
                                                    std::vector<Shared<Settings>>(400));
  std::vector<std::thread> threads;
  for (int t = 0; t < 2; ++t)
    threads.emplace_back([&, t] {
      const CountCopiesLocally scope;
      for (size_t c = t; c < 400; c += 2)
        for (size_t m = 0; m < models.size(); ++m) copies[m][c] = models[m];
    });
  for (std::thread& t : threads) t.join();
  for (size_t m = 0; m < models.size(); ++m) {
    for (const Shared<Settings>& c : copies[m]) ASSERT_TRUE(c.SameAs(models[m]));
    // Editing a copy gives it its own; the model and the other copies keep theirs.
    copies[m][5].Edit().range = 100;
    EXPECT_DOUBLE_EQ(models[m]->range, static_cast<double>(m));
    EXPECT_DOUBLE_EQ(copies[m][6]->range, static_cast<double>(m));
    EXPECT_FALSE(copies[m][5].SameAs(models[m]));
  }
  // Every copy gone: the models are the last holders, and edit in place.
  copies.clear();
  for (Shared<Settings>& model : models) {
    const Settings* before = &*model;
    model.Edit().name = "edited";
    EXPECT_EQ(&*model, before);
  }
}

TEST(SharedSettingsTest, NestedScopesCountOnceTheOutermostCloses) {
  Shared<Settings> model(Settings{0.2, "ring"});
  std::vector<Shared<Settings>> copies;
  copies.reserve(10);
  {
    const CountCopiesLocally outer;
    {
      const CountCopiesLocally inner;
      for (int i = 0; i < 5; ++i) copies.push_back(model);
    }
    for (int i = 0; i < 5; ++i) copies.push_back(model);
  }
  copies[0].Edit().range = 7;  // not the last holder: a copy of its own
  EXPECT_DOUBLE_EQ(model->range, 0.2);
  EXPECT_DOUBLE_EQ(copies[9]->range, 0.2);
}

}  // namespace
}  // namespace swarmsim
