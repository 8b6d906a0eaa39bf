// The unit that builds the tests' shared precompiled header (CMakeLists.txt: vines_test_pch).
