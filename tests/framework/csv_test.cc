// framework/csv.h: what the program's CSV writer writes, its reader reads
// back field for field (a sweep reads metrics.csv with it: metric names
// with a comma were split, their values averaged into one metric).
#include "framework/csv.h"

#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

namespace swarmsim {
namespace {

TEST(CsvTest, FieldsComeBackAsTheyWereWritten) {
  const std::vector<std::string> fields = {"plain", "a,b",   "c\"d",   "new\nline",
                                           "",      "\"q\"", "cr\r\n", "ünï"};
  std::ostringstream out;
  for (size_t i = 0; i < fields.size(); ++i) {
    out << (i ? "," : "");
    WriteCsvField(out, fields[i]);
  }
  out << "\n";
  std::string joined;
  for (size_t i = 0; i < fields.size(); ++i) {
    if (i) joined += ',';
    joined += CsvField(fields[i]);
  }
  EXPECT_EQ(out.str(), joined + "\n");
  EXPECT_EQ(CsvField("a,b"), "\"a,b\"");
  EXPECT_EQ(CsvField("c\"d"), "\"c\"\"d\"");
  EXPECT_EQ(CsvField("plain"), "plain");
  std::istringstream in(out.str() + "x,y\r\n");
  std::vector<std::string> read;
  ASSERT_TRUE(ReadCsvRecord(in, &read));
  EXPECT_EQ(read, fields);
  ASSERT_TRUE(ReadCsvRecord(in, &read));  // a CRLF line
  EXPECT_EQ(read, (std::vector<std::string>{"x", "y"}));
  EXPECT_FALSE(ReadCsvRecord(in, &read));
}

TEST(CsvTest, ARecordTheInputEndsInsideIsNone) {
  for (const std::string torn : {"3,0.3,bot#0,x", "1,\"open quote\n", "1,\"a\"\"b"}) {
    std::istringstream in(torn);
    std::vector<std::string> read;
    EXPECT_FALSE(ReadCsvRecord(in, &read)) << torn;
  }
}

}  // namespace
}  // namespace swarmsim
