// SPDX-License-Identifier: GPL-3.0-or-later
// The long variant of tests/engine/test_block_size_identity.cpp (label soak): every
// shipped surface on 8 s walks between two pauses (every layer sleeps and wakes), host blocks 1,
// 2, 37, 63, 65, 128, 256, 1000, 4096 and a size that changes at every call, compared bit for
// bit with the 64-frame render.
#include "tests/engine/BlockSizeIdentity.h"

using namespace underfoot::test::blocksize;

TEST(BlockSizeIdentitySoak, EveryShippedSurfaceOnLongWalksForManyHostBlockSizes) {
    expectSurfacesBlockSizeIdentical(8.0, {2, 63, 65, 128, 4096});
}
