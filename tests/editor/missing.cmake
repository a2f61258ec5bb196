# Registered instead of the editor tests when the editor cannot be built: fails with the reason.
message(FATAL_ERROR "the graph editor is not built: ${WHY}. Run `bash tools/install-deps.sh`, then configure and "
                    "build again (tools/build.sh does both).")
