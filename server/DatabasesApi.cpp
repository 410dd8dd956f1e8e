#include "DatabasesApi.hpp"

#include "CoverageExport.hpp"
#include "Ids.hpp"
#include "Problem.hpp"
#include "fields/FieldDatabase.hpp"

namespace rcfd::server {

namespace {
// Validation reads frames through a bounded cache instead of loading a large upload into RAM.
constexpr std::int64_t kValidationCacheBytes = 64ll << 20;

nlohmann::json toJson(const DatabaseRecord& db) {
  return {{"id", db.id},
          {"frames", db.frames},
          {"bytes", db.bytes},
          {"created_at", db.createdAt},
          {"links", {{"self", "/v1/databases/" + db.id}}}};
}
}  // namespace

std::filesystem::path DatabasesApi::temporaryUploadPath() const {
  auto dir = config_.databaseDir() / "incoming";
  std::filesystem::create_directories(dir);
  return dir / (newId() + ".h5.part");
}

StringResponse DatabasesApi::accept(const std::filesystem::path& file, const Target& target) {
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(file, ec);
  if (ec || bytes == 0) {
    std::filesystem::remove(file, ec);
    return problem(http::status::bad_request, "empty-upload", "Empty upload",
                   "the request body must be an HDF5 field database (docs/formats.md)", target.path);
  }
  DatabaseRecord db;
  try {
    std::lock_guard lock(hdf5Mutex());
    const auto opened = FieldDatabase::open(file.string(), FrameStorage{kValidationCacheBytes});
    db.frames = opened->frameCount();
    // Every frame is read once: a NaN or Inf is refused now (InputError naming the dataset and the
    // frame), not when a spray job reaches that frame hours later.
    for (int i = 0; i < db.frames; ++i) (void)opened->frame(i);
  } catch (const InputError& e) {
    std::filesystem::remove(file, ec);
    // The source is "upload", not the server's temporary file name.
    return invalidInput(InputError("upload", e.violations()), target.path);
  } catch (const std::exception& e) {
    std::filesystem::remove(file, ec);
    std::string what = e.what();
    for (auto at = what.find(file.string()); at != std::string::npos; at = what.find(file.string()))
      what.replace(at, file.string().size(), "upload");
    return problem(http::status::unprocessable_entity, "invalid-database", "Invalid field database",
                   "the upload is not a readable field database: " + what, target.path);
  }
  db.id = newId();
  db.bytes = static_cast<std::int64_t>(bytes);
  db.path = (config_.databaseDir() / (db.id + ".h5")).string();
  db.createdAt = nowRfc3339();
  std::filesystem::rename(file, db.path, ec);
  if (ec) {
    std::filesystem::remove(file, ec);
    return problem(http::status::internal_server_error, "storage-failed", "Storage failed",
                   "cannot move the upload into " + config_.databaseDir().string(), target.path);
  }
  store_.insertDatabase(db);
  auto res = jsonResponse(http::status::created, toJson(db));
  res.set(http::field::location, "/v1/databases/" + db.id);
  return res;
}

Response DatabasesApi::get(const std::string& id, const Target& target) {
  const auto db = store_.database(id);
  if (!db)
    return problem(http::status::not_found, "database-not-found", "Database not found",
                   "there is no uploaded database with id \"" + id + "\"", target.path);
  return jsonResponse(http::status::ok, toJson(*db));
}

}  // namespace rcfd::server
