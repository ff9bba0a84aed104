// The translation unit that builds a kind's precompiled header (cmake/precompiled_headers.cmake).
