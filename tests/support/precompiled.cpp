// The source the tests' precompiled header is built with (adit_test_pch in
// tests/CMakeLists.txt); it holds nothing of its own.
