# Installation and export (filled in by the packaging work).
include(GNUInstallDirs)
