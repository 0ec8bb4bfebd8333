#include <gtest/gtest.h>
TEST(ExportTest, Placeholder) {}
