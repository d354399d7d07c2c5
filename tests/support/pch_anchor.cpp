// The one source file of nsg_test_pch (tests/CMakeLists.txt): a target needs a file to
// compile its precompiled header with the test binaries' flags.
