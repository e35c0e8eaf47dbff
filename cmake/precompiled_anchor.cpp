// Compiled only to make the entry points' precompiled header (CMakeLists.txt, masa_entry_point).
