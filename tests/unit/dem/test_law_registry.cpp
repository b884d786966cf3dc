// Contact and bond laws registered by name (src/dem/laws.hpp): every registered law owns its
// name and its keys; the scenario picks the law by name; a key of a law that is not the active
// one is refused with a message naming the active law; unknown names list the registered ones.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "core/error.hpp"
#include "dem/dem_params.hpp"
#include "dem/laws.hpp"
#include "io/scenario.hpp"

using namespace ff;
using namespace ff::dem;

namespace {

// Every law of `list` declares keys only under `section`.*, none declared by two laws, and
// finds itself by name.
template <class List> void check_list(List list, const std::string& section) {
  std::set<std::string> names, keys;
  int index = 0;
  for_each_law(list, [&]<class Law>(std::type_identity<Law>) {
    EXPECT_TRUE(names.insert(std::string(Law::name)).second) << "duplicate law name " << Law::name;
    EXPECT_EQ(law_index_of(list, Law::name), index) << Law::name;
    EXPECT_EQ(law_name(list, index), Law::name);
    EXPECT_NE(law_names(list).find("\"" + std::string(Law::name) + "\""), std::string::npos);
    ParamTable own;
    Law::declare(own);
    for (const auto& spec : own.specs()) {
      EXPECT_EQ(spec.key.rfind(section + ".*.", 0), 0u) << Law::name << " declares " << spec.key;
      EXPECT_TRUE(keys.insert(spec.key).second) << spec.key << " declared by two laws";
      EXPECT_FALSE(spec.unit.empty()) << spec.key << ": no unit";
      EXPECT_TRUE(spec.default_value.has_value()) << spec.key << ": no default";
    }
    ++index;
  });
  EXPECT_EQ(index, List::size);
  EXPECT_EQ(law_index_of(list, "no_such_law"), -1);
}

std::string build_error(const std::string& toml) {
  ParamTable t;
  declare_dem_params(t);
  try {
    const Config cfg = load_scenario(t, "<test>", toml, {});
    (void)build_materials(cfg);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

const std::string kGroup = "[dem.group.rock]\ndensity = 2600\n";

}  // namespace

TEST(LawRegistry, EveryLawOwnsItsNameAndKeys) {
  check_list(ContactLaws{}, "dem.contact");
  check_list(BondLaws{}, "dem.bond");
}

TEST(LawRegistry, TheScenarioPicksTheLawByName) {
  ParamTable t;
  declare_dem_params(t);
  const Config cfg = load_scenario(t, "<test>",
                                   "[dem]\ncontact_law = \"hertz_mindlin\"\nbond_law = \"rotational\"\n" + kGroup +
                                       "[dem.contact.rock-rock]\nshear_modulus = 3e9\n[dem.bond.rock-rock]\n"
                                       "youngs_modulus = 5e9\nfriction_angle = 30\n",
                                   {});
  const Materials m = build_materials(cfg);
  EXPECT_TRUE(m.contact_is<HertzMindlinContact>());
  EXPECT_TRUE(m.bond_is<RotationalBond>());
  EXPECT_EQ(m.contact_law_name(), "hertz_mindlin");
  EXPECT_EQ(m.bond_law_name(), "rotational");
  ASSERT_EQ(m.contact_params<HertzMindlinContact>().size(), 1u);
  EXPECT_EQ(m.contact_params<HertzMindlinContact>()[0].shear_modulus, 3e9);
  EXPECT_EQ(m.bond_params<RotationalBond>()[0].youngs_modulus, 5e9);
  EXPECT_TRUE(m.contact_params<LinearContact>().empty()) << "only the active law's table is filled";
}

TEST(LawRegistry, KeyOfAnInactiveLawNamesTheActiveLaw) {
  // The example: a parallel-bond key with the rotational law was silently accepted.
  const std::string e = build_error("[dem]\nbond_law = \"rotational\"\n" + kGroup + "[dem.contact.rock-rock]\n"
                                    "[dem.bond.rock-rock]\nfriction_angle = 30\ntensile_strength = 1e3\n");
  EXPECT_NE(e.find("tensile_strength"), std::string::npos) << e;
  EXPECT_NE(e.find("\"rotational\""), std::string::npos) << e;
  EXPECT_NE(e.find("parallel"), std::string::npos) << e;
  const std::string h = build_error("[dem]\n" + kGroup + "[dem.contact.rock-rock]\npoisson = 0.3\n[dem.bond.rock-rock]\n");
  EXPECT_NE(h.find("\"linear\""), std::string::npos) << h;
  EXPECT_NE(h.find("hertz_mindlin"), std::string::npos) << h;
}

TEST(LawRegistry, UnknownLawNameListsTheRegisteredOnes) {
  ParamTable t;
  declare_dem_params(t);
  try {
    (void)load_scenario(t, "<test>", "[dem]\ncontact_law = \"jkr\"\n" + kGroup, {});
    FAIL() << "an unknown contact law must be refused";
  } catch (const InputError& e) {
    const std::string what = e.what();
    for_each_law(ContactLaws{}, [&]<class Law>(std::type_identity<Law>) {
      EXPECT_NE(what.find("\"" + std::string(Law::name) + "\""), std::string::npos) << what;
    });
  }
}
