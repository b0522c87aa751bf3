#include "swarm/kilobot/build.h"

#include <elf.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <set>
#include <string>
#include <vector>

#include "framework/error.h"
#include "framework/shared_library.h"

extern char** environ;

namespace swarmsim::kilobot {
namespace fs = std::filesystem;
namespace {

// The compiler, objcopy: $CC / $OBJCOPY or the system's.
std::string Tool(const char* variable, const char* fallback) {
  const char* value = std::getenv(variable);
  return value != nullptr && value[0] != 0 ? value : fallback;
}

// Runs argv (no shell), its output and errors passed through; returns its
// exit status (127: could not start it).
int Run(const std::vector<std::string>& argv) {
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid;
  if (posix_spawnp(&pid, args[0], nullptr, nullptr, args.data(), environ) != 0) return 127;
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return 127;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// What the build needs to know of a relocatable ELF64 object: its writable
// data sections (renamed so that each robot gets its own copy), whether
// it defines main, and whether it calls delay() (the runtime then runs
// setup() and loop() on a stack of the robot's own, so that delay can wait).
struct ObjectInfo {
  std::set<std::string> data, bss;  // section names: initialised, zeroed
  bool defines_main = false;
  bool calls_delay = false;
  bool ok = false;
};

ObjectInfo Inspect(const fs::path& path) {
  ObjectInfo info;
  const std::string bytes = ReadFile(path);
  if (bytes.size() < sizeof(Elf64_Ehdr)) return info;
  Elf64_Ehdr header;
  std::memcpy(&header, bytes.data(), sizeof header);
  if (std::memcmp(header.e_ident, ELFMAG, SELFMAG) != 0 || header.e_ident[EI_CLASS] != ELFCLASS64)
    return info;
  const size_t count = header.e_shnum;
  if (header.e_shoff + count * sizeof(Elf64_Shdr) > bytes.size() || header.e_shstrndx >= count)
    return info;
  std::vector<Elf64_Shdr> sections(count);
  std::memcpy(sections.data(), bytes.data() + header.e_shoff, count * sizeof(Elf64_Shdr));
  const auto text_at = [&](const Elf64_Shdr& table, size_t offset) -> std::string {
    const size_t at = table.sh_offset + offset;
    if (at >= bytes.size()) return {};
    return std::string(bytes.c_str() + at, strnlen(bytes.c_str() + at, bytes.size() - at));
  };
  const Elf64_Shdr& names = sections[header.e_shstrndx];
  for (const Elf64_Shdr& s : sections) {
    const bool writable = (s.sh_flags & SHF_ALLOC) != 0 && (s.sh_flags & SHF_WRITE) != 0 &&
                          (s.sh_flags & SHF_TLS) == 0;
    if (writable && s.sh_type == SHT_PROGBITS) info.data.insert(text_at(names, s.sh_name));
    if (writable && s.sh_type == SHT_NOBITS) info.bss.insert(text_at(names, s.sh_name));
    if (s.sh_type == SHT_SYMTAB && s.sh_link < count && s.sh_entsize == sizeof(Elf64_Sym)) {
      const Elf64_Shdr& strings = sections[s.sh_link];
      for (size_t i = 0; i < s.sh_size / sizeof(Elf64_Sym); ++i) {
        Elf64_Sym sym;
        const size_t at = s.sh_offset + i * sizeof sym;
        if (at + sizeof sym > bytes.size()) break;
        std::memcpy(&sym, bytes.data() + at, sizeof sym);
        if (sym.st_shndx != SHN_UNDEF && ELF64_ST_BIND(sym.st_info) == STB_GLOBAL &&
            text_at(strings, sym.st_name) == "main")
          info.defines_main = true;
        if (sym.st_shndx == SHN_UNDEF && text_at(strings, sym.st_name) == "delay")
          info.calls_delay = true;
      }
    }
  }
  info.ok = true;
  return info;
}

// objcopy renaming the writable sections of `object` to kilo_data, zeroed
// ones too (so that the region is one block: the linker stores their zeros),
// and main to kilobot_program_main for the program.
int Rename(const fs::path& object, bool program) {
  const ObjectInfo info = Inspect(object);
  if (!info.ok) {
    std::cerr << "error: " << object.string() << " is not an ELF64 object\n";
    return 1;
  }
  std::vector<std::string> argv = {Tool("OBJCOPY", "objcopy")};
  for (const std::string& name : info.data)
    argv.push_back("--rename-section=" + name + "=kilo_data");
  for (const std::string& name : info.bss)
    argv.push_back("--rename-section=" + name + "=kilo_data,alloc,load,contents,data");
  if (program) {
    argv.push_back("--redefine-sym=main=kilobot_program_main");
    // exit() would end swarmsim: the runtime's ends the run naming the robot.
    argv.push_back("--redefine-sym=exit=kilobot_exit");
    // Signal handlers would be the process's: the runtime's refuse.
    for (const char* f :
         {"signal", "sigaction", "bsd_signal", "sysv_signal", "__sysv_signal", "sigset"})
      argv.push_back(std::string("--redefine-sym=") + f + "=kilobot_" + f);
  }
  argv.push_back(object.string());
  return Run(argv);
}

// A temporary folder removed when it goes out of scope.
struct TempFolder {
  fs::path path;
  TempFolder() {
    std::string pattern = (fs::temp_directory_path() / "swarmsim-kilobot-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) throw Error("cannot create a temporary folder");
    path = pattern;
  }
  ~TempFolder() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

bool ValidName(const std::string& name) {
  if (name.empty() || name.size() > 64) return false;
  for (char c : name)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.'))
      return false;
  return true;
}

std::string Quoted(const std::string& text) {  // a C string literal for -D
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

}  // namespace

std::string RuntimeFolder() {
  if (const char* dir = std::getenv("SWARMSIM_KILOBOT_DIR"); dir != nullptr && dir[0] != 0)
    return dir;
  std::error_code ec;
  if (fs::exists(fs::path(SWARMSIM_KILOBOT_SOURCE_DIR) / "runtime" / "host.c", ec))
    return SWARMSIM_KILOBOT_SOURCE_DIR;
  // An install: bin/swarmsim and share/swarmsim/kilobot.
  const fs::path installed = ProgramFolder() / ".." / "share" / "swarmsim" / "kilobot";
  if (fs::exists(installed / "runtime" / "host.c", ec))
    return installed.lexically_normal().string();
  throw Error(std::string("cannot find the Kilobot runtime (include/, runtime/): not at ") +
              SWARMSIM_KILOBOT_SOURCE_DIR + " nor " + installed.string() +
              " ($SWARMSIM_KILOBOT_DIR names its folder)");
}

int Build(const BuildOptions& options) {
  std::error_code ec;
  const fs::path source = fs::absolute(options.source, ec);
  if (options.source.empty() || !fs::exists(source, ec))
    throw Error("kilobot build: " + options.source + ": no such file");
  if (!fs::is_regular_file(source, ec))  // a folder said "no such file"
    throw Error("kilobot build: " + options.source + ": " +
                (fs::is_directory(source, ec) ? "a folder" : "not an ordinary file") +
                ": give the program's .c file");
  const std::string name = options.name.empty() ? source.stem().string() : options.name;
  if (!ValidName(name))
    throw Error("kilobot build: '" + name +
                "' cannot name a controller (letters, digits, '_', '-', '.'; --name NAME)");
  const fs::path output = options.output.empty() ? source.parent_path() / (name + ".so")
                                                 : fs::absolute(options.output, ec);
  const fs::path folder = RuntimeFolder();
  const fs::path include = folder / "include", runtime = folder / "runtime";
  // framework/plugin_api.h: the source tree's, or the install's copy.
  fs::path root = SWARMSIM_SOURCE_ROOT;
  if (!fs::exists(root / "framework" / "plugin_api.h", ec)) root = folder;
  TempFolder temp;
  const std::string cc = Tool("CC", "cc");
  // -fstack-clash-protection: a frame larger than a page touches each page
  // in turn, so a large local array meets the guard page below a robot's
  // stack (a stack overflow, named) instead of writing past it.
  const std::vector<std::string> common = {"-fPIC",
                                           "-O2",
                                           "-fno-common",
                                           "-g0",
                                           "-fstack-clash-protection",
                                           "-DSWARMSIM_KILOBOT=1",
                                           "-I" + include.string()};
  const auto compile = [&](const fs::path& file, const fs::path& object,
                           const std::vector<std::string>& extra) {
    std::vector<std::string> argv = {cc};
    argv.insert(argv.end(), common.begin(), common.end());
    argv.insert(argv.end(), extra.begin(), extra.end());
    argv.insert(argv.end(), {"-c", file.string(), "-o", object.string()});
    return Run(argv);
  };
  // 1. The program, with the user's flags.
  const fs::path program = temp.path / "program.o";
  if (const int status = compile(source, program, options.cc_flags); status != 0) {
    if (status == 127)
      std::cerr << "error: kilobot build: cannot run the C compiler '" << cc << "' ($CC)\n";
    else
      std::cerr << "error: " << source.string() << " does not compile (" << cc
                << " exited with status " << status << "; its messages are above)\n";
    return 2;
  }
  const ObjectInfo program_info = Inspect(program);
  if (!program_info.defines_main) {
    std::cerr << "error: " << source.string()
              << " defines no main(): a Kilobot program's main() calls kilo_init() and "
                 "kilo_start(setup, loop)\n";
    return 2;
  }
  // 2. The runtime: its per-robot part and the host glue.
  const fs::path kilolib = temp.path / "kilolib.o", host = temp.path / "host.o";
  if (compile(runtime / "kilolib.c", kilolib, {"-I" + runtime.string()}) != 0 ||
      compile(runtime / "host.c", host,
              {"-I" + runtime.string(), "-I" + root.string(), "-pthread",
               "-DKILOBOT_NAME=" + Quoted(name), "-DKILOBOT_SOURCE=" + Quoted(source.string()),
               program_info.calls_delay ? "-DKILOBOT_DELAY=1" : "-DKILOBOT_DELAY=0"}) != 0) {
    std::cerr << "error: kilobot build: the runtime in " << runtime.string()
              << " does not compile with " << cc << "\n";
    return 1;
  }
  // 3. Each robot's own globals: the writable sections renamed.
  if (Rename(program, true) != 0 || Rename(kilolib, false) != 0) {
    std::cerr << "error: kilobot build: objcopy failed ($OBJCOPY)\n";
    return 1;
  }
  // 4. The plugin: only its entry points exported, every other symbol bound
  // inside it (a program's rand() is the runtime's, never libc's).
  const fs::path exports = temp.path / "exports.map";
  std::ofstream(exports) << "{ global: swarmsim_plugin_abi_version; swarmsim_plugin_register; "
                            "swarmsim_kilobot_copy; local: *; };\n";
  const fs::path partial = output.string() + ".partial";
  fs::create_directories(output.parent_path(), ec);
  const std::vector<std::string> link = {cc,
                                         "-shared",
                                         "-o",
                                         partial.string(),
                                         program.string(),
                                         kilolib.string(),
                                         host.string(),
                                         "-Wl,--version-script=" + exports.string(),
                                         "-Wl,-z,now",
                                         "-Wl,--no-undefined",
                                         "-pthread",
                                         "-lm",
                                         "-ldl"};
  if (const int status = Run(link); status != 0) {
    fs::remove(partial, ec);
    std::cerr << "error: " << source.string() << " does not link (" << cc << " exited with status "
              << status << "; its messages are above)\n";
    return 2;
  }
  fs::rename(partial, output, ec);
  if (ec) {
    std::cerr << "error: cannot write " << output.string() << ": " << ec.message() << "\n";
    return 1;
  }
  if (!options.quiet)
    std::cout << "built " << output.string() << ": native controller '" << name
              << "' (a world: plugins: [" << output.stem().string()
              << "], and native_controller: " << name << ")\n";
  return 0;
}

}  // namespace swarmsim::kilobot
