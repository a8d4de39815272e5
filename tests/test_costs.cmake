# Costs of the longest Catch2 cases (seconds on this machine, ctest -j2), read by ctest after
# catch_discover_tests' list (tests/CMakeLists.txt says why). ctest ignores a name it does not know
# (no message, no failure), so a case renamed here only loses its place at the front of a fresh
# checkout's run; the order, not a result, depends on this list.
set_tests_properties(
  "plate report writes index.html whose every figure exists"
  PROPERTIES COST 60)
set_tests_properties(
  "the half-turn pair broken by rz about its centre: fig4's fixed point unique, every run at the target"
  PROPERTIES COST 37)
set_tests_properties(
  "without the hold a sink cones: released at the target the part walks about the centre at the coning rate"
  PROPERTIES COST 20)
set_tests_properties(
  "a rigid part's sink: its position ends at the target whatever its orientation, held"
  PROPERTIES COST 15)
set_tests_properties(
  "progress lines only for a person watching: quiet when stderr is not a terminal"
  PROPERTIES COST 14)
set_tests_properties(
  "plate design: a verified sink is a scene whose own field has its one stable fixed point at the target, and a failed design exits 4 and writes nothing"
  PROPERTIES COST 13)
set_tests_properties(
  "stick-slip: fig6's pivoting cycles agree with the regularised-friction limit to 1e-7 v_ref"
  PROPERTIES COST 12)
set_tests_properties(
  "the predicted sds match the spread of seeded identifications under the suggested motion"
  PROPERTIES COST 30)
