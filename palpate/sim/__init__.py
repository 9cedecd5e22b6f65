"""The world the hardware would be: scenes, contact mechanics, virtual clock, device emulators."""
