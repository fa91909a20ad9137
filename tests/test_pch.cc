// Empty: the target fitcal_test_pch exists to build the tests' precompiled header once.
