#include <gtest/gtest.h>

#include "nsg/core/error.h"
#include "nsg/core/sha256.h"
#include "test_support.h"

namespace nsg {

TEST(Sha256, KnownVectors) {
  EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
}

TEST(Sha256, IncrementalEqualsOneShotAndFile) {
  Sha256 h;
  h.update("a");
  h.update("bc");
  EXPECT_EQ(h.hex_digest(), sha256_hex("abc"));
  test::TempDir dir("sha");
  test::write_text(dir / "f.txt", "abc");
  EXPECT_EQ(sha256_file(dir / "f.txt"), sha256_hex("abc"));
  EXPECT_THROW(sha256_file(dir / "missing"), IoError);
}

}  // namespace nsg
