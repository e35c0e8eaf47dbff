// Malformed specs: each must throw a ConfigError naming the source file and the key path.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "common/core/config_error.hpp"
#include "common/symmetry/symmetry_spec.hpp"

namespace masa::sym {
namespace {

const char* kSource = "bad_spec.yaml";

// Runs parseString and returns the error; fails the test if nothing or something else is thrown.
ConfigError specErrorOf(const std::string& yaml) {
  try {
    SymmetrySpec::parseString(yaml, kSource);
  } catch (const ConfigError& e) {
    return e;
  }
  ADD_FAILURE() << "no ConfigError for:\n" << yaml;
  return ConfigError("", "", "");
}

void expectError(const std::string& yaml, const std::string& key, const std::string& fragment = "") {
  const ConfigError e = specErrorOf(yaml);
  const std::string what = e.what();
  EXPECT_EQ(e.key(), key) << what;
  EXPECT_EQ(e.file(), kSource);
  EXPECT_NE(what.find(kSource), std::string::npos) << what;
  EXPECT_NE(what.find(key), std::string::npos) << what;
  EXPECT_NE(what.find(fragment), std::string::npos) << "'" << fragment << "' not in: " << what;
}

// A valid spec around the given observation central/limb lists and group.
std::string spec(const std::string& central, const std::string& limb = "[{name: j, kind: invariant}]",
                 const std::string& group = "{type: reflection, axis: y}") {
  return "name: t\ngroup: " + group + "\nobservation:\n  central: " + central + "\n  limb: " + limb +
         "\naction:\n  limb: [{name: u, kind: invariant}]\n";
}

const std::string kC3 = "{type: rotation, axis: z, order: 3}";
const std::string kC4 = "{type: rotation, axis: z, order: 4}";

TEST(SymmetrySpecErrors, ValidBaseSpecParses) {
  EXPECT_NO_THROW(SymmetrySpec::parseString(spec("[{name: a, kind: odd}]"), kSource));
  EXPECT_NO_THROW(SymmetrySpec::parseString(spec("[{name: a, kind: vector3}]", "[]", kC3), kSource));
}

TEST(SymmetrySpecErrors, UnknownKindListsValidKinds) {
  expectError(spec("[{name: a, kind: odd}]", "[{name: j, kind: invariant}, {name: k, kind: polar}]"),
              "observation.limb[1].kind", "valid kinds: invariant, odd, polar_x");
}

TEST(SymmetrySpecErrors, MissingRequiredKeys) {
  expectError(spec("[{kind: odd}]"), "observation.central[0].name", "missing");
  expectError(spec("[{name: a}]"), "observation.central[0].kind", "missing");
  expectError("name: t\nobservation: {central: [{name: a, kind: odd}]}\naction: {central: [{name: u, kind: odd}]}\n",
              "group", "missing");
  expectError(spec("[{name: a, kind: odd}]", "[]", "{type: rotation, axis: z}"), "group.order", "missing");
  expectError(spec("[{name: a, kind: odd}]", "[]", "{axis: z}"), "group.type", "missing");
  expectError("name: t\ngroup: {type: reflection, axis: y}\nobservation: {central: [{name: a, kind: odd}]}\n",
              "action", "missing");
}

TEST(SymmetrySpecErrors, UnknownKeysAreRejectedEverywhere) {
  expectError(spec("[{name: a, kind: odd, cuont: 2}]"), "observation.central[0].cuont", "unknown key");
  expectError(spec("[{name: a, kind: odd}]", "[]", "{type: reflection, axis: y, ordr: 2}"), "group.ordr",
              "unknown key");
  expectError(spec("[{name: a, kind: odd}]") + "extra: 1\n", "extra", "unknown key");
  expectError("name: t\ngroup: {type: reflection, axis: y}\nobservation: {centrl: []}\naction: {limb: []}\n",
              "observation.centrl", "unknown key");
}

TEST(SymmetrySpecErrors, KeyGivenTwice) {
  expectError(spec("[{name: a, kind: odd, kind: invariant}]"), "observation.central[0].kind", "twice");
}

TEST(SymmetrySpecErrors, LimbSignsWrongLengthOrValueOrPlace) {
  expectError(spec("[]", "[{name: j, kind: invariant, limb_signs: [1, -1, 1]}]", kC4), "observation.limb[0].limb_signs",
              "N = 4");
  expectError(spec("[]", "[{name: j, kind: invariant, limb_signs: [1, 2]}]"), "observation.limb[0].limb_signs[1]",
              "+1 or -1");
  expectError(spec("[{name: a, kind: odd, limb_signs: [1, -1]}]"), "observation.central[0].limb_signs",
              "only limb entries");
}

TEST(SymmetrySpecErrors, OddUnderOddOrderRotation) {
  expectError(spec("[{name: a, kind: odd}]", "[]", kC3), "observation.central[0].kind", "not a representation");
}

TEST(SymmetrySpecErrors, QuaternionUnderEvenOrderRotationSuggestsVectors) {
  expectError(spec("[{name: q, kind: quaternion}]", "[]", kC4), "observation.central[0].kind", "projected gravity");
  expectError(spec("[{name: q, kind: quaternion}]", "[]", kC4), "observation.central[0].kind", "no linear lift");
}

TEST(SymmetrySpecErrors, SingleComponentsAndVector2MustBeClosedUnderRotation) {
  expectError(spec("[{name: x, kind: polar_x}]", "[]", kC3), "observation.central[0].kind", "mixes");
  expectError(spec("[{name: z, kind: polar_z}, {name: w, kind: axial_y}]", "[]", kC3), "observation.central[1].kind",
              "perpendicular");
  expectError(spec("[{name: v, kind: vector2}]", "[]", "{type: rotation, axis: x, order: 3}"),
              "observation.central[0].kind", "mixes");
}

TEST(SymmetrySpecErrors, DuplicateNameInBlock) {
  expectError(spec("[{name: a, kind: odd}, {name: b, kind: odd}, {name: a, kind: invariant}]"),
              "observation.central[2].name", "duplicate");
}

TEST(SymmetrySpecErrors, SwapWithProblems) {
  expectError(spec("[{name: a, kind: odd, swap_with: b}]"), "observation.central[0].swap_with", "no entry named 'b'");
  expectError(spec("[{name: a, kind: odd, swap_with: b}, {name: b, kind: invariant}]"),
              "observation.central[0].swap_with", "same kind");
  expectError(spec("[{name: a, kind: odd, swap_with: b}, {name: b, kind: odd, swap_with: c}, {name: c, kind: odd}]"),
              "observation.central[0].swap_with", "swaps with 'c'");
  expectError(spec("[{name: a, kind: odd, swap_with: b}, {name: b, kind: odd}, {name: c, kind: odd, swap_with: b}]"),
              "observation.central[2].swap_with", "already paired");
  expectError(spec("[{name: a, kind: vector3, swap_with: b}, {name: b, kind: vector3}]"),
              "observation.central[0].swap_with", "1-D");
  expectError(spec("[{name: a, kind: invariant, swap_with: b}, {name: b, kind: invariant}]", "[]", kC3),
              "observation.central[0].swap_with", "reflection");
  expectError(spec("[]", "[{name: j, kind: invariant, swap_with: k}, {name: k, kind: invariant}]"),
              "observation.limb[0].swap_with", "only central");
  expectError(spec("[{name: a, kind: odd, swap_with: a}]"), "observation.central[0].swap_with", "itself");
}

TEST(SymmetrySpecErrors, CountOnlyForOneDimensionalKindsAndPositive) {
  expectError(spec("[{name: a, kind: vector3, count: 2}]"), "observation.central[0].count", "1-D");
  expectError(spec("[{name: a, kind: odd, count: 0}]"), "observation.central[0].count", ">= 1");
  expectError(spec("[{name: a, kind: odd, count: two}]"), "observation.central[0].count", "integer");
}

TEST(SymmetrySpecErrors, BadGroup) {
  expectError(spec("[{name: a, kind: odd}]", "[]", "{type: glide, axis: y}"), "group.type", "reflection, rotation");
  expectError(spec("[{name: a, kind: odd}]", "[]", "{type: reflection, axis: w}"), "group.axis", "x, y, z");
  expectError(spec("[{name: a, kind: odd}]", "[]", "{type: reflection, axis: y, order: 4}"), "group.order", "2");
  expectError(spec("[{name: a, kind: odd}]", "[]", "{type: rotation, axis: z, order: 1}"), "group.order", ">= 2");
}

TEST(SymmetrySpecErrors, EmptySpecHasNoDimensions) {
  expectError("name: t\ngroup: {type: reflection, axis: y}\nobservation: {central: [], limb: []}\n"
              "action: {central: [{name: u, kind: odd}]}\n",
              "observation", "no dimensions");
  expectError("name: t\ngroup: {type: reflection, axis: y}\nobservation: {central: [{name: a, kind: odd}]}\n"
              "action: {}\n",
              "action", "no dimensions");
}

TEST(SymmetrySpecErrors, BadNamesAndDocumentShape) {
  expectError(spec("[{name: 2nd, kind: odd}]"), "observation.central[0].name", "not a valid name");
  expectError("- just\n- a list\n", "<document>", "mapping");
  expectError(spec("{name: a, kind: odd}"), "observation.central", "list");
}

TEST(SymmetrySpecErrors, YamlSyntaxErrorNamesFileAndLine) {
  expectError("name: t\ngroup: {type: reflection, axis: y\nobservation: x\n", "<yaml>", "line");
}

TEST(SymmetrySpecErrors, MissingFileNamesThePath) {
  const std::string path = "/nonexistent/dir/no_such_spec.yaml";
  try {
    SymmetrySpec::load(path);
    FAIL() << "no error for a missing file";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

TEST(SymmetrySpecErrors, LoadedFileErrorsNameTheFileAndKey) {
  const auto path = std::filesystem::temp_directory_path() / "masa_test_symmetry_bad_spec.yaml";
  {
    std::ofstream out(path);
    out << spec("[{name: a, kind: odd}, {name: b, kind: vektor3}]");  // the central list is line 4
  }
  try {
    SymmetrySpec::load(path.string());
    ADD_FAILURE() << "no error for a bad kind";
  } catch (const ConfigError& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.file(), path.string());
    EXPECT_NE(what.find(path.string()), std::string::npos) << what;
    EXPECT_EQ(e.key(), "observation.central[1].kind");
    EXPECT_NE(what.find("line 4"), std::string::npos) << what;
  }
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace masa::sym
