// The translation unit that builds tests/TestPrecompiled.h once for every test binary.
