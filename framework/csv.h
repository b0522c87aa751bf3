// CSV as the program writes it (metrics.csv, graphs/*.csv, report --csv)
// and reads it back (a sweep's runs): RFC 4180, a field quoted when it holds
// a comma, a quote or a line break, its quotes doubled. The writer and the
// reader in one place, so that what one writes the other reads.
#pragma once

#include <istream>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace swarmsim {

// `text` as one CSV field.
std::string CsvField(std::string_view text);
// The same, written to `out` (no string made: metrics.csv's rows).
void WriteCsvField(std::ostream& out, std::string_view text);

// The next record's fields. False at the end of the input, and for a record
// the input ends inside (no line break after it, or an open quote): a torn
// last row, as a run killed while writing leaves it.
bool ReadCsvRecord(std::istream& in, std::vector<std::string>* fields);

}  // namespace swarmsim
