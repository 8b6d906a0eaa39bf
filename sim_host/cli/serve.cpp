#include "sim_host/cli/serve.hpp"

#include <cstdio>
#include <stdexcept>

#ifdef VINES_HAVE_MONITOR
#include "sim_host/monitor/server.hpp"
#include "sim_host/monitor/view.hpp"
#include "sim_host/monitor/watch.hpp"
#endif

namespace vines::cli {

CLI::Option* add_serve(CLI::App& cmd, std::string* at, const std::string& help) {
  return cmd
      .add_option_function<std::string>(
          "--serve",
          [at](const std::string& v) {
#ifdef VINES_HAVE_MONITOR
            try {
              host::monitor::parse_address("--serve", v);
            } catch (const std::exception& e) {
              throw CLI::ValidationError(e.what(), CLI::ExitCodes::ValidationError);
            }
#endif
            *at = v;
          },
          help)
      ->type_name("ADDRESS");  // (the help cuts a type name at its first colon)
}

#ifdef VINES_HAVE_MONITOR
struct ServedPage::Impl {
  host::monitor::Hub hub;
  host::monitor::PageWatch watch{hub};
  std::unique_ptr<host::monitor::PageServer> server;
};

ServedPage::ServedPage() : impl_(std::make_unique<Impl>()) {}
void ServedPage::listen(const std::string& command, const std::string& at) {
  impl_->server = std::make_unique<host::monitor::PageServer>(impl_->hub, host::monitor::parse_address("--serve", at));
  std::fprintf(stderr, "%s: the page is at %s\n", command.c_str(), impl_->server->url().c_str());
  std::fflush(stderr);
}
ServedPage::~ServedPage() = default;
host::HilWatch* ServedPage::watch() { return &impl_->watch; }
void ServedPage::load(const std::string& path) { host::monitor::load_run(path, &impl_->hub); }
void ServedPage::stop(std::chrono::milliseconds linger, bool hold) {
  if (impl_->server) impl_->server->stop(linger, hold);
}
#else
struct ServedPage::Impl {};
ServedPage::ServedPage() {
  throw std::runtime_error("--serve: this vines was built without the monitoring page (libmicrohttpd not found: "
                           "install libmicrohttpd-dev and reconfigure)");
}
ServedPage::~ServedPage() = default;
void ServedPage::listen(const std::string&, const std::string&) {}
host::HilWatch* ServedPage::watch() { return nullptr; }
void ServedPage::load(const std::string&) {}
void ServedPage::stop(std::chrono::milliseconds, bool) {}
#endif

}  // namespace vines::cli
