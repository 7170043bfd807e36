// Fuzz harness: stroke files through the entry every caller uses (format detection, the JSON
// stroke reader, validation), then the first steps of the player that replays them.
#include "core/io/stroke.h"
#include "core/io/stroke_player.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  wb::fuzz::expect_clean([&] {
    wb::StrokePlayer player(wb::parse_stroke_text(wb::fuzz::text_of(data, size), "fuzz.json"));
    wb::PlayerStep step;
    for (int i = 0; i < 64 && player.next(step); ++i) {
    }
  });
  return 0;
}
