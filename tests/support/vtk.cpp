#include "support/vtk.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

namespace demcal::test {

namespace {

// void, so that ASSERT_* can stop the reading at the first broken count.
void read_polydata(const std::string& text, long particles, bool contacts,
                   std::set<std::string>& names) {
  std::stringstream s(text);
  std::string line;
  std::getline(s, line);
  EXPECT_EQ(line, "# vtk DataFile Version 3.0");
  std::getline(s, line);  // title
  EXPECT_LE(line.size(), 256u);
  std::getline(s, line);
  EXPECT_EQ(line, "ASCII");
  std::getline(s, line);
  EXPECT_EQ(line, "DATASET POLYDATA");
  std::string word, type;
  long n = -1, cells = -1;
  s >> word >> n >> type;
  ASSERT_EQ(word, "POINTS");
  EXPECT_EQ(n, particles);
  EXPECT_EQ(type, "double");
  for (long i = 0; i < 3 * n; ++i) {
    double v;
    ASSERT_TRUE(s >> v) << "point " << i / 3;
    EXPECT_TRUE(std::isfinite(v)) << "point " << i / 3;
  }
  long count = -1, size = -1;
  s >> word >> count >> size;
  ASSERT_EQ(word, "VERTICES");
  EXPECT_EQ(count, n);
  EXPECT_EQ(size, 2 * n);
  for (long i = 0; i < count; ++i) {
    long one, index;
    ASSERT_TRUE(s >> one >> index);
    EXPECT_EQ(one, 1);
    EXPECT_EQ(index, i);
  }
  long lines = -1;
  s >> word >> lines >> size;
  ASSERT_EQ(word, "LINES");
  if (contacts) {
    EXPECT_GT(lines, 0);  // a loaded packing has contacts
  }
  EXPECT_EQ(size, 3 * lines);
  for (long i = 0; i < lines; ++i) {
    long two, a, b;
    ASSERT_TRUE(s >> two >> a >> b);
    EXPECT_EQ(two, 2);
    EXPECT_TRUE(a >= 0 && a < n && b >= 0 && b < n && a != b) << a << " " << b;
  }
  // POINT_DATA n: SCALARS/VECTORS blocks of n values; CELL_DATA n + lines.
  long data_count = -1;
  s >> word >> data_count;
  ASSERT_EQ(word, "POINT_DATA");
  EXPECT_EQ(data_count, n);
  for (;;) {
    if (!(s >> word)) break;
    if (word == "CELL_DATA") {
      s >> data_count;
      EXPECT_EQ(data_count, n + lines);
      cells = data_count;
      continue;
    }
    std::string name, vtype;
    s >> name >> vtype;
    names.insert(name);
    int components = 1;
    if (word == "SCALARS") {
      s >> components;
      std::string lut, table;
      s >> lut >> table;
      EXPECT_EQ(lut, "LOOKUP_TABLE");
    } else {
      ASSERT_EQ(word, "VECTORS") << "unexpected section";
      components = 3;
    }
    for (long i = 0; i < data_count * components; ++i) {
      double v;
      ASSERT_TRUE(s >> v) << name << " value " << i;
    }
  }
  EXPECT_EQ(cells, n + lines);
}

}  // namespace

std::set<std::string> check_vtk_polydata(const std::string& text, long particles, bool contacts) {
  std::set<std::string> names;
  read_polydata(text, particles, contacts, names);
  return names;
}

}  // namespace demcal::test
