from matedit.cli import main

raise SystemExit(main())
