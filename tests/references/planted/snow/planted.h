// References planted for the reference check's own test (CTest
// references_resolve_catches). Never compiled. These resolve: the gradient of
// Horn 1981, this file snow/planted.h, the page docs/references.md.
// These do not: the table in terrain/parameters.h, the hash of Burley 2020
// and the decision of SPEC 3a.
#pragma once
