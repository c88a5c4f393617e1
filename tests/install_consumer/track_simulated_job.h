// The consumer's one job on the installed library, shared by a program (track_simulated) and a
// plugin loaded at run time (track_plugin, through load_plugin): render a short simulated
// colonoscopy, track it from its first depth map (the paper's tracking experiment) and print how
// the run went. C linkage, so that load_plugin finds it by this name.
#pragma once

extern "C" {
// Writes the sequence and the run into WORK_FOLDER; prints this library's version and a line
// "status S, tracked N/M, RMSE E mm". Returns 0 when every frame was tracked.
int TrackSimulatedSequence(const char* work_folder);
}
