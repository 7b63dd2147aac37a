// The unit that builds the tests' precompiled header (tests/CMakeLists.txt, rwcalc_test_pch); it has
// no code of its own.
