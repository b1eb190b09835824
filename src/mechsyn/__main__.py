from mechsyn.cli.main import main

main()
